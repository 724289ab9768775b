// Writes small run files for the command-line tests of `crowdrecon render`
// (until `crowdrecon simulate` can make them):
//   crowdrecon_make_test_run DIR [BODY.json]
// DIR/run.sqlite     12 people in counter-flow in a periodic 3 m x 1.5 m
//                    corridor, 21 frames at 10 fps (0 to 2 s) with contacts;
//                    bodies from BODY.json (crowdrecon-body, e.g.
//                    venues/bodies/thorax-18.json) or the 8-vertex test thorax
// DIR/empty.sqlite   the same run's header with no frame (a run that died at once)
// DIR/packed.sqlite  run.sqlite with its frames packed (run.frames = "packed")
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "../unit/render_scene.hpp"

namespace {

using namespace crowdrecon;
using namespace crowdrecon::engine;

// The body file's vertices and radius; read directly (format of
// docs/bodies.md) so that this tool depends only on the engine and scenario.
BodyShape ReadBody(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open body file");
  const nlohmann::json j = nlohmann::json::parse(in);
  BodyShape shape;
  shape.radius_m = j.at("radius_m").get<double>();
  for (const auto& v : j.at("vertices_m")) shape.vertices.push_back({v.at(0).get<double>(), v.at(1).get<double>()});
  return shape;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s DIR [BODY.json]\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const BodyShape shape = argc == 3 ? ReadBody(argv[2]) : testing::ThoraxLikeShape();
    const testing::CorridorScene scene;
    {
      Simulation sim(testing::CounterFlowCorridor(shape, scene));
      testing::WriteCorridorRun(dir / "run.sqlite", sim, scene, 21, 10.0, /*record_periodic_box=*/true);
    }
    {
      Simulation sim(testing::CounterFlowCorridor(shape, scene));
      testing::WriteCorridorRun(dir / "empty.sqlite", sim, scene, 0, 10.0, false);
    }
    {
      Simulation sim(testing::CounterFlowCorridor(shape, scene));
      testing::WriteCorridorRun(dir / "packed.sqlite", sim, scene, 21, 10.0, true, /*packed=*/true);
    }
    std::printf("wrote %s/run.sqlite, %s/empty.sqlite and %s/packed.sqlite\n", dir.c_str(), dir.c_str(), dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon_make_test_run: %s\n", e.what());
    return 1;
  }
  return 0;
}
