"""An SVG drawn by a script, as a headless browser draws it: the PNG beside it.

Shared by the scripts that draw their own SVG figures
(studies/itaewon-design-envelope/itaewon-envelope.py,
studies/night-cheap-model/night-cheap-model.py, which import it from this
folder). Does nothing where no Chromium is installed
(scripts/install-deps.sh installs it).
"""
import os
import shutil
import subprocess


def svg_to_png(svg, png, width, height):
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        return False
    subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    f"--screenshot={os.path.abspath(png)}", f"--window-size={width},{height}",
                    "file://" + os.path.abspath(svg)],
                   check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return True
