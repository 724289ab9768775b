// The pieces every HTML report of the project shares (the injury-risk report,
// the validation report): the style sheet, tables, the page's self-check in
// the browser, and printing the page to PDF with headless Chromium, the one
// program outside the build that a report calls.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace crowdrecon::reports::html {

// The style sheet (A4 print rules included).
std::string Css();
// A table; cells are HTML as given.
std::string Table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows);
// A script that reports a missing image or fewer than `figures` figures as a
// console error (the browser tests fail on console errors).
std::string SelfCheckScript(std::size_t figures);
// `given`, or the first of chromium, chromium-browser, google-chrome on PATH
// ("" if none).
std::string FindChromium(const std::string& given);
// The browser that will print (FindChromium), or the clear error (PrintPdf's,
// saying how to install one) before any work is done.
std::string ChromiumOrError(const std::string& given);
// Prints `html` to `pdf` with `chromium` (its profile and log beside the PDF,
// removed whatever happens). InputError naming the browser and its log's
// start if it fails; a clear one, saying how to install it, when `chromium`
// is "".
void PrintPdf(const std::string& chromium, const std::filesystem::path& html, const std::filesystem::path& pdf);

}  // namespace crowdrecon::reports::html
