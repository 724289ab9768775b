// Observation inputs (issue 22): the observation spec (JSON), the camera
// homography (JSON), and an observation file with its CSV series. The first
// byte picks the parser, the rest is its input:
//   0: observe::ParseObservationSpec
//   1: observe::ParseHomography
//   2: observe::ReadObservation, the rest as the series CSV (the JSON beside
//      it records the CSV's real checksum, so that the CSV parser is reached)
//   3: observe::ReadObservation, the rest as the observation JSON (its CSV
//      "o.csv" holds only the header)
#include <fstream>

#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/observe/homography.hpp"
#include "crowdrecon/observe/observation.hpp"
#include "fuzz_harness.hpp"

namespace {

constexpr const char* kHeader = "time_s,quantity,where,direction,unit,value,uncertainty,samples\n";

std::string ObservationJson(const std::string& csv_sha) {
  return R"({"format": "crowdrecon-observation", "version": 1,
 "source": {"file": "run.sqlite", "sha256": "", "format": "crowdrecon-run", "method": "trajectories", "options": {}},
 "spec": {"format": "crowdrecon-observation-spec", "version": 1, "regions": [{"name": "r", "polygon": [[0, 0], [1, 0], [1, 1]]}]},
 "time": {"t0_s": 0, "bin_s": 0.2, "bins": 5},
 "series_file": {"name": "o.csv", "sha256": ")" + csv_sha + R"("},
 "series": [{"quantity": "speed", "where": "r", "direction": "forward", "unit": "m/s"}],
 "events": [], "notes": []})";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  if (size == 0) return 0;
  const std::string text = fuzz::Text(data + 1, size - 1);
  const std::filesystem::path json = fuzz::ScratchDir() / "o.json", csv = fuzz::ScratchDir() / "o.csv";
  switch (data[0] % 4) {
    case 0:
      return fuzz::Parse([&] { (void)observe::ParseObservationSpec(text, "spec.json"); });
    case 1:
      return fuzz::Parse([&] { (void)observe::ParseHomography(text, "h.json"); });
    case 2:
      std::ofstream(csv, std::ios::binary) << text;
      std::ofstream(json, std::ios::binary) << ObservationJson(Sha256Hex(text));
      return fuzz::Parse([&] { (void)observe::ReadObservation(json); });
    default:
      std::ofstream(csv, std::ios::binary) << kHeader;
      std::ofstream(json, std::ios::binary) << text;
      return fuzz::Parse([&] { (void)observe::ReadObservation(json); });
  }
}
