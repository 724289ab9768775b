#!/usr/bin/env bash
# The report as its readers see it (issue 21): two seeds of a short hallway
# run compared with a third, report.html opened in headless Chromium (fails on
# any console message -- the page reports a missing image or figure on the
# console -- and checks that its self-check ran), a screenshot saved, and
# report.pdf's first and last pages turned into pictures with pdftoppm.
#   report_browser.sh CROWDRECON SCENARIO OUT_DIR
set -euo pipefail
exe=$1; scenario=$2; out=$3
rm -rf "$out"; mkdir -p "$out"
chromium=$(command -v chromium || command -v chromium-browser || true)
[[ -n $chromium ]] || { echo "report_browser.sh: chromium is not installed (scripts/install-deps.sh installs it)"; exit 1; }
command -v pdftoppm >/dev/null || { echo "report_browser.sh: pdftoppm is not installed (poppler-utils)"; exit 1; }
# Seeds 7, 8 (the ensemble) and 9 (the comparison): the scenario with its
# seed changed and its paths made absolute.
for seed in 7 8 9; do
  python3 "$(dirname "$0")/../../scripts/scenario-with.py" "$scenario" "$out/s$seed.json" population.seed=$seed
  "$exe" simulate "$out/s$seed.json" -o "$out/run-$seed.sqlite" -q > /dev/null
done
"$exe" report "$out/run-7.sqlite" "$out/run-8.sqlite" --compare "$out/run-9.sqlite" --label "seeds 7, 8" \
  --compare-label "seed 9" -o "$out/report" -q | tee "$out/summary.txt"
grep -q "seeds 7, 8 (2 runs)" "$out/summary.txt"
test -s "$out/report/report.pdf" && test -s "$out/report/people.csv"
# The page in the browser: its console must stay silent, its self-check must have run.
"$chromium" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$out/profile" \
  --enable-logging=stderr --v=0 --virtual-time-budget=5000 --dump-dom "file://$out/report/report.html" \
  > "$out/dom.html" 2> "$out/console.txt" || { cat "$out/console.txt"; exit 1; }
if grep -E "CONSOLE|Uncaught" "$out/console.txt"; then echo "report_browser.sh: console messages above"; exit 1; fi
# The check can fail: the same page with a missing image must be reported.
sed 's#</body>#<img src="missing.png"></body>#' "$out/report/report.html" > "$out/broken.html"
"$chromium" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$out/profile" \
  --enable-logging=stderr --v=0 --virtual-time-budget=5000 --dump-dom "file://$out/broken.html" > /dev/null 2> "$out/broken.txt" || true
grep -q "CONSOLE.*missing image" "$out/broken.txt" || { echo "report_browser.sh: a missing image went unnoticed"; exit 1; }
figures=$(grep -o 'data-figures="[0-9]*"' "$out/dom.html" | grep -o '[0-9]*' || true)
[[ -n $figures && $figures -ge 9 ]] || { echo "report_browser.sh: the page's self-check did not run or found $figures figures"; exit 1; }
"$chromium" --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir="$out/profile" --hide-scrollbars \
  --window-size=1200,2400 --screenshot="$out/screenshot.png" "file://$out/report/report.html" > /dev/null 2>&1
test -s "$out/screenshot.png"
pages=$(pdfinfo "$out/report/report.pdf" 2>/dev/null | awk '/^Pages:/ {print $2}' || echo 0)
pdftoppm -r 60 -png -f 1 -l 1 "$out/report/report.pdf" "$out/page-first"
pdftoppm -r 60 -png -f "${pages:-1}" -l "${pages:-1}" "$out/report/report.pdf" "$out/page-last"
ls "$out"/page-first*.png "$out"/page-last*.png > /dev/null
echo "report_browser.sh: $figures figures in the page, $pages PDF pages, screenshot $out/screenshot.png"
