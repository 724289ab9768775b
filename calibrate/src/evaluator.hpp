// Evaluations: a parameter set's statistics over the calibration's seeds,
// from runs made through the sweep machinery and cached (internal to
// calibrate/).
//
// A set's key is the SHA-256 of the calibration's fingerprint and the exact
// values. Every run is observed right after it ends (the sweep's after_run
// hook, on the worker and MPI rank that ran it) with each distinct spec of the
// calibration's observations, and the observation is written, compactly, to
// DIR/cache/<key>/seed<N>-<spec>.json (or seed<N>.failed for a run that could
// not be placed or went numerically wrong); the run file is then deleted. A
// set is run only if some seed's file is missing: the sets of one request that
// need runs form one sweep (each set a variant, K seeds), in
// DIR/batches/<key of the batch>/, which resumes like any sweep.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/calibrate/statistics.hpp"

namespace crowdrecon::calibrate {

struct SetResult {
  std::vector<double> values;  // one per parameter
  std::string key;
  // [seed][statistic]: NaN where a window holds no value or the run failed.
  std::vector<std::vector<double>> per_seed;
  std::vector<std::string> failures;  // one message per failed seed
  std::vector<double> mean, sd;       // per statistic over the seeds with a value (NaN if none)
  std::size_t order = 0;              // when it was first evaluated (0, 1, ...)
  std::string stage;                  // which stage asked first
};

class Evaluator {
 public:
  Evaluator(const CalibrationSpec& spec, const std::vector<Statistic>& statistics, std::filesystem::path dir,
            int jobs, bool show_progress);
  // The sets' results, running what is not cached. False if the sweep was
  // interrupted (nothing is returned then).
  bool Evaluate(const std::vector<std::vector<double>>& sets, const std::string& stage, std::vector<SetResult>* out);
  // Every set evaluated so far, in order of first evaluation.
  std::vector<const SetResult*> All() const;
  std::size_t runs_simulated() const { return runs_simulated_; }
  bool coordinator() const { return coordinator_; }

  // A set's values mapped onto the bounds' unit box and back.
  std::vector<double> ToUnit(const std::vector<double>& values) const;
  std::vector<double> FromUnit(const std::vector<double>& unit) const;

 private:
  std::string KeyOf(const std::vector<double>& values) const;
  bool Cached(const std::string& key) const;
  SetResult Load(const std::vector<double>& values, const std::string& key) const;
  // Runs the sets through one sweep (resumable: the same sets, the same
  // folder). `attempt` > 0: again in a folder of its own, for sets whose
  // runs that sweep had already recorded as done while their observations
  // are gone from the cache (deleted by hand): its record would skip them.
  bool RunBatch(const std::vector<std::vector<double>>& sets, const std::vector<std::string>& keys, int attempt = 0);

  const CalibrationSpec& spec_;
  const std::vector<Statistic>& statistics_;
  std::filesystem::path dir_;
  int jobs_;
  bool show_progress_;
  bool coordinator_ = true;
  std::size_t runs_simulated_ = 0;
  // Distinct observation specs (JSON) and, per observation, its spec's index.
  std::vector<std::string> spec_json_, spec_tag_;
  std::vector<observe::ObservationSpec> specs_;  // parsed once, used by every run's hook
  std::vector<std::size_t> spec_of_observation_;
  std::map<std::string, SetResult> known_;
};

}  // namespace crowdrecon::calibrate
