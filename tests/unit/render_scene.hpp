// A small counter-flow scene written to a run file, for the render tests and
// the command-line tests' data (tests/tools/make_test_run.cpp).
#pragma once

#include <cmath>
#include <filesystem>
#include <string>

#include "crowdrecon/scenario/run_record.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine::testing {

struct CorridorScene {
  double length_m = 3.0;  // along x, periodic
  double width_m = 1.5;   // across, walls at y = 0 and y = width_m
  int columns = 4;        // people per row
  int rows = 3;
};

// People on a lattice, in a checkerboard of two groups: group 0 walks toward
// +x, group 1 (counter-flow) toward -x, so that they collide head-on within a
// second. Walls along both long sides; periodic along x.
inline WorldDef CounterFlowCorridor(const BodyShape& shape, const CorridorScene& c = {}) {
  WorldDef def;
  def.shapes.push_back(shape);
  def.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  def.targets.push_back(geometry::NavigationField::Constant({-1.0, 0.0}));
  const double dx = c.length_m / c.columns, dy = c.width_m / c.rows;
  for (int j = 0; j < c.rows; ++j)
    for (int i = 0; i < c.columns; ++i) {
      PersonDef p;
      p.shape = 0;
      SetMassFromShape(shape, 1000.0, p);  // rho of the paper (kg/m^2)
      p.group = static_cast<std::uint32_t>((i + j) % 2);
      p.target = p.group;
      p.position_m = {(i + 0.5) * dx, (j + 0.5) * dy};
      p.angle_rad = p.group == 0 ? 0.0 : std::acos(-1.0);
      p.desired_speed_m_per_s = 1.2;
      def.people.push_back(p);
    }
  def.walls.push_back({{{0.0, 0.0}, {c.length_m, 0.0}}, false, 0.0});
  def.walls.push_back({{{0.0, c.width_m}, {c.length_m, c.width_m}}, false, 0.0});
  def.periodic.x = true;
  def.periodic.min_m = {0.0, 0.0};
  def.periodic.max_m = {c.length_m, c.width_m};
  return def;
}

inline std::string RectangleWkt(double length_m, double width_m) {
  const std::string l = std::to_string(length_m), w = std::to_string(width_m);
  return "POLYGON ((0 0, " + l + " 0, " + l + " " + w + ", 0 " + w + ", 0 0))";
}

// Runs `sim` for `frames` frames at `fps` and writes each with its contacts.
// Without `record_periodic_box` the run table's periodic_box is blanked, as in
// a run file that does not record it.
inline void WriteCorridorRun(const std::filesystem::path& file, Simulation& sim, const CorridorScene& c,
                             int frames, double fps, bool record_periodic_box, bool packed = false) {
  runfile::RunHeader header;
  header.packed = packed;
  header.scenario_json = "{\"test\": \"counter-flow corridor\"}";
  header.scenario_origin = "tests/unit/render_scene.hpp";
  header.walkable_wkt = RectangleWkt(c.length_m, c.width_m);
  header.output_fps = fps;
  header.time_step_s = sim.time_step_s();
  runfile::RunFileWriter writer = scenario::CreateRunFile(file, header, sim, {"to_exit", "to_court"});
  // RunFileWriter records the periodic box itself; an empty value stands for
  // run files that do not (the renderer must cope with both).
  if (!record_periodic_box) writer.SetRunValue("periodic_box", "");
  for (int k = 0; k < frames; ++k) {
    if (k > 0) sim.AdvanceTo(k / fps);
    scenario::WriteFrame(writer, sim, k, {}, /*with_contacts=*/true);
  }
  writer.SetStatus("complete");
}

}  // namespace crowdrecon::engine::testing
