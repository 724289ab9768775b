// Calibration files (calibrate::ParseCalibration), from memory, then the
// statistics they ask for from their observations. Paths resolve against
// tests/data/calibration/, as for the seeds (its hallway-3s.observation.json).
#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/calibrate/statistics.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  return fuzz::Parse([&] {
    const calibrate::CalibrationSpec spec = calibrate::ParseCalibration(
        fuzz::Text(data, size), "fuzz-calibration.json", fuzz::SourceDir() / "tests/data/calibration");
    (void)calibrate::ObservedStatistics(spec);
  });
}
