// Calibration: fits scenario values (by default the model's back force Γ,
// torsion stiffness λ and restitution ε) to observation files with Ceres, and
// says how well each is determined (docs/calibration.md).
//
//   calibrate::Options options;
//   options.calibration_file = "venues/madrid-arena/calibrations/hallway-recovery.json";
//   options.output_dir = "out/calibration";
//   calibrate::Summary s = calibrate::Calibrate(options);   // DIR/calibration.json, report.txt, pictures
//
// Named stages (docs/calibration.md): 1. read the calibration and the
// observations; 2. measure the objective's noise (optional); 3. search from
// every start (a quadratic surrogate over a design, refined; or Ceres with
// central differences); 4. uncertainty at the best fit (a local design,
// Ceres' covariance, the seed-and-observation bootstrap); 5. profiles; 6. the
// posterior; 7. the footage design (what more recordings would determine);
// 8. the outputs. Every parameter set is K runs (the same seeds at every set: common
// random numbers) run through the sweep machinery (sweep/): on the local
// cores or over MPI ranks, each set cached in DIR/cache/ once run, so an
// interrupted calibration resumes where it stopped and repeats nothing.
#pragma once

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"

namespace crowdrecon::calibrate {

struct Options {
  std::filesystem::path calibration_file;
  std::filesystem::path output_dir;
  int jobs = 0;                // runs at a time (0: every core; under MPI 1 per rank)
  bool show_progress = false;  // the sweeps' live progress line on stderr (a terminal)
  bool show_stages = false;    // a line on stderr as each stage begins (a log too: long work says where it is)
  bool IsValid(std::string* error) const;
};

// One parameter's result.
struct ParameterResult {
  std::string path;
  double value = 0.0;
  double min = 0.0, max = 0.0;  // its bounds
  // 95 % interval from Ceres' covariance at the optimum (NaN when the
  // covariance could not be computed) and the bootstrap's percentiles.
  double sigma = 0.0, lo95 = 0.0, hi95 = 0.0;
  double bootstrap_sigma = 0.0, bootstrap_lo95 = 0.0, bootstrap_hi95 = 0.0;
  // The posterior's median, standard deviation and central 68 % and 95 %
  // intervals (a flat prior over the bounds; NaN: no posterior). The
  // intervals whose coverage is checked (docs/calibration.md, "The posterior").
  double posterior_median = 0.0, posterior_sd = 0.0;
  double posterior_lo68 = 0.0, posterior_hi68 = 0.0, posterior_lo95 = 0.0, posterior_hi95 = 0.0;
  // The covariance's 95 % half-width as a fraction of the value (NaN where
  // either is unknown or the value is 0): how precisely "determined".
  double RelativeHalfWidth95() const { return value != 0.0 ? 1.96 * sigma / std::abs(value) : std::numeric_limits<double>::quiet_NaN(); }
  // "determined", "bounded on one side" or "undetermined", with the reason.
  std::string determination;
  std::string reason;
};

struct Summary {
  std::string name;
  std::string approach;
  bool interrupted = false;
  bool coordinator = true;  // false on MPI ranks other than 0 (which print nothing)
  std::vector<ParameterResult> parameters;
  std::vector<std::vector<double>> correlation;
  double chi2 = 0.0;
  int degrees_of_freedom = 0;
  std::size_t sets_evaluated = 0;  // parameter sets (each K runs)
  std::size_t runs = 0;            // runs simulated now (cached ones not counted)
  std::size_t starts = 0;
  bool starts_agree = false;
  double wall_s = 0.0;
  std::filesystem::path json_file, report_file;
  std::vector<std::string> notes;  // what was cleaned up (partial runs of earlier, interrupted calibrations)

  std::string BriefReport() const;
};

// A previous calibration folder (it holds .crowdrecon-calibration), which
// `calibrate -o` continues (common/output_path.hpp).
OutputKind CalibrationFolderOutput();

// Runs (or continues) the calibration. Throws InputError for a bad
// calibration file, observation or output folder.
Summary Calibrate(const Options& options);

}  // namespace crowdrecon::calibrate
