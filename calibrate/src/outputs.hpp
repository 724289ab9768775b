// What a calibration found, as its outputs need it, and the writers of
// DIR/calibration.json, evaluations.csv, report.txt and the pictures
// (internal to calibrate/).
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/calibrate/calibrate.hpp"
#include "evaluator.hpp"
#include "fit.hpp"
#include "footage.hpp"

namespace crowdrecon::calibrate {

struct StartResult {
  std::vector<double> start;  // values
  std::vector<double> found;  // values
  double surrogate_chi2 = 0.0;
  double simulated_chi2 = 0.0;
  std::string termination;
};

struct NoiseResult {
  std::string parameter;
  double step = 0.0;              // in the parameter's units
  double chi2_noise_sd = 0.0;     // scatter of chi2 around a quadratic along the line
  double residual_noise_sd = 0.0; // pooled scatter of the residuals around lines
  double slope_signal = 0.0;      // median |d residual| over the gradient step, in units of that scatter
};

// One simulated point of a parameter's profile (calibrate.cpp, "5. Profiles").
struct ProfilePoint {
  double value = 0.0;           // the parameter's
  std::vector<double> values;   // every parameter's (the others re-fitted)
  double chi2 = 0.0;            // simulated
  // What the quadratic of every set predicted there (NaN: none).
  double surrogate_chi2 = std::numeric_limits<double>::quiet_NaN();
  // chi2 less the lowest of the profile and the best fit, and the 2.5 and
  // 97.5 percentiles of that difference over redraws of the seeds (NaN: no redraws).
  double delta_chi2 = 0.0;
  double delta_lo95 = std::numeric_limits<double>::quiet_NaN(), delta_hi95 = std::numeric_limits<double>::quiet_NaN();
};

struct CalibrationResult {
  const CalibrationSpec* spec = nullptr;
  Objective objective;
  std::vector<NoiseResult> noise;
  // The seeds' covariance behind the weights (fit.hpp, PooledSeedCovariance).
  struct SeedCorrelation {
    double shrinkage = 0.0;         // of the sample correlations toward zero
    double effective_values = 0.0;  // independent simulated values they amount to
    std::size_t values = 0;         // distinct simulated values with a spread
    std::size_t sets = 0;           // pooled over
    double freedom = 0.0;           // its degrees of freedom (0: not estimated)
  } seed_correlation;
  std::vector<StartResult> starts;
  std::vector<double> best;  // values
  double best_simulated_chi2 = 0.0;
  SetResult best_set;        // the best set's runs
  std::string surrogate_form;
  std::vector<double> surrogate_rms;  // per statistic, the local surrogate's fit
  bool covariance_ok = false;
  std::string covariance_reason;
  std::vector<double> covariance;  // values' units, row-major
  std::vector<int> without_effect;  // parameters no statistic depends on at the best fit
  std::vector<std::vector<double>> bootstrap;  // replicates' values
  // The posterior (fit.hpp, SamplePosterior): its samples' values, and how
  // they were had.
  struct Posterior {
    std::vector<std::vector<double>> samples;  // values, chain after chain
    std::size_t chains = 0;
    double acceptance = 0.0;
    std::vector<double> r_hat;            // per parameter
    std::string surrogate_form;           // the quadratic over every set evaluated
    std::size_t sets = 0;                 // ... of this many sets
    std::vector<double> lack_of_fit_sd;   // per statistic: the surrogate's error beyond the seeds' (NaN: not fitted)
    double scale = 1.0;                   // the likelihood's widening: max(1, chi2 at the best fit / degrees of freedom)
    double bandwidth = 0.0;               // the surrogate's (fraction of the box; inf: the quadratic over the whole box)
    std::size_t seed_functions = 0;       // the seeds' surfaces sampled as the means' error (0: none)
    double likelihood_power = 0.0;        // m of the estimated covariance's likelihood (fit.hpp, EstimatedCovariance; 0: Gaussian)
    std::vector<double> bandwidth_scores; // leave-one-out error of each candidate
    std::string note;                     // why there is none
  } posterior;
  // d (simulated mean of statistic j) / d (parameter i) at the best fit, from
  // the local quadratic (statistics x parameters, row-major, the parameters'
  // units; NaN: not fitted), and what it says about more footage.
  std::vector<double> jacobian;
  FootageDesign footage;
  std::vector<std::vector<ProfilePoint>> profiles;
  bool profiles_refitted = false;  // the others re-fitted at each point (else held at the best fit)
  Summary summary;
};

// v with `digits` significant digits ("-" when not finite), for reports.
std::string Fixed(double v, int digits = 3);

// Fills the summary's parameters: values, intervals, determination
// (calibration_summary.cpp).
void Summarise(const CalibrationSpec& spec, CalibrationResult& r);

// Writes every output into `dir` and fills summary.json_file / report_file.
void WriteOutputs(const std::filesystem::path& dir, const Evaluator& evaluator, CalibrationResult* result);

}  // namespace crowdrecon::calibrate
