// A calibration's cached observations (DIR/cache/KEY/seedN-TAG.json: a run's
// bins, series and events, which a resumed calibration reads instead of
// running that set again; calibrate::ReadCachedObservation), through a
// scratch file, then every statistic of the hallway recovery calibration
// (venues/madrid-arena/calibrations/hallway-recovery.json, read once)
// computed from it, as the calibration does. The seed is a cache file of
// that calibration.
#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/calibrate/statistics.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  // The calibration and its statistics, read once per process.
  static const calibrate::CalibrationSpec spec =
      calibrate::LoadCalibration(fuzz::SourceDir() / "venues/madrid-arena/calibrations/hallway-recovery.json");
  static const std::vector<calibrate::Statistic> statistics = calibrate::ObservedStatistics(spec);
  const std::filesystem::path file = fuzz::WriteScratchFile(data, size, "json");
  return fuzz::Parse([&] {
    const observe::Observation simulated = calibrate::ReadCachedObservation(file);
    std::vector<double> values;
    for (std::size_t i = 0; i < spec.observations.size(); ++i)
      calibrate::SimulatedStatistics(i, simulated, statistics, &values);
  });
}
