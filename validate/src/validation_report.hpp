// The validation report (internal to validate/): report.html (self-contained,
// inline SVG), report.pdf printed from it, results.json and results.csv.
#pragma once

#include <string>

#include "crowdrecon/validate/validate.hpp"

namespace crowdrecon::validate {

// Writes the report's files into options.output_dir (each complete before it
// is renamed into place) and names them in *summary.
void WriteValidationReport(const ValidateOptions& options, const std::string& chromium, ValidateSummary* summary);

}  // namespace crowdrecon::validate
