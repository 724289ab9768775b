"""An SVG drawn by a script, as a headless browser draws it: the PNG beside it.

Shared by the scripts that draw their own SVG figures
(studies/itaewon-design-envelope/itaewon-envelope.py,
studies/night-cheap-model/night-cheap-model.py, which import it from this
folder). Does nothing where no Chromium is installed
(scripts/install-deps.sh installs it). The PNG is written whole
(scripts/script_guard.py): the browser draws it under a temporary name beside
it, which is renamed over it once complete, so a failed or killed browser
leaves no partial picture (and the previous one, if any, as it was).
"""
import contextlib
import os
import shutil
import subprocess

import script_guard


def svg_to_png(svg, png, width, height):
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        return False
    script_guard.remove_stale_partials(png)
    tmp = script_guard.partial_path(png)
    with script_guard.TerminateAsExit():
        try:
            subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                            f"--screenshot={os.path.abspath(tmp)}", f"--window-size={width},{height}",
                            "file://" + os.path.abspath(svg)],
                           check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            if os.path.isfile(tmp) and os.path.getsize(tmp) > 0:
                os.replace(tmp, png)
        finally:
            with contextlib.suppress(OSError):
                os.remove(tmp)
    return True
