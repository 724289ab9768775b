// The definition of a world handed to the engine: shapes, people, walls,
// targets, periodic box and floor slope, all as plain data (geometry is
// prepared at the edges; no CGAL, OpenCV or Ceres here).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/engine/parameters.hpp"
#include "crowdrecon/geometry/navigation.hpp"

namespace crowdrecon::engine {

// A body shape in its own frame: centroid at the origin, chest facing +x
// (ERRATA 6), vertices counter-clockwise; 1 vertex = disk, 2 = capsule.
struct BodyShape {
  std::vector<Vec2> vertices;
  double radius_m = 0.05;  // sphero-radius
  // Largest distance of a vertex from the centroid (m); filled by the
  // engine. (The narrow phase keeps its own geometry: narrow_phase.hpp.)
  double core_radius_m = 0.0;
};

// A wall: an open or closed polyline swept by a disk of radius radius_m, of
// infinite mass. A person's vertex meets the whole polyline (its closest
// point), so walls made of many segments act as one smooth surface with no
// double counting at joints. radius_m may be 0 (a bare line).
struct Wall {
  std::vector<Vec2> points;
  bool closed = false;
  double radius_m = 0.0;
};

// Motion state of a person.
enum class PersonState : std::uint8_t {
  kWalking = 0,
  kFallen = 1,   // an obstacle: neither translates nor rotates (paper, "falls")
  kRemoved = 2,  // not in the venue (left it, or not yet arrived: an empty
                 // slot that Simulation::Spawn may fill); takes no part in the dynamics
};

struct PersonDef {
  Vec2 position_m;
  double angle_rad = 0.0;  // orientation theta: direction the chest faces
  Vec2 velocity_m_per_s;
  double angular_velocity_rad_per_s = 0.0;
  double mass_kg = 55.0;
  double inertia_kg_m2 = 0.0;  // I^z about the centroid
  std::uint32_t shape = 0;     // index into WorldDef::shapes
  double desired_speed_m_per_s = 1.0;  // v0 of eq. (3)
  std::uint32_t target = 0;            // index into WorldDef::targets
  std::uint32_t group = 0;             // e.g. 0 = toward the exit, 1 = counter-flow
  PersonState state = PersonState::kWalking;
};

// The box of a periodic run (common/periodic_box.hpp): positions are wrapped
// into it along periodic axes.
using crowdrecon::PeriodicBox;

struct FloorSlope {
  Vec2 downhill;          // unit vector (0, 0 = flat)
  double gradient = 0.0;  // rise over run (e.g. 0.30 m / 12 m = 0.025)
  std::vector<Vec2> region;  // the polygon where the floor slopes (a person's centre inside); empty: everywhere
};

// Where the narrow phase and contact law of person pairs run. The results
// are the same, bit for bit (engine/src/cuda_collide.hpp); kCuda needs a build
// with CUDA and a device, and is refused with a clear message otherwise.
enum class ComputeDevice : std::uint8_t {
  kCpu = 0,
  kCuda = 1,
};
const char* ToString(ComputeDevice d);
bool FromString(const std::string& s, ComputeDevice* d);

struct WorldDef {
  ModelParameters parameters;
  std::vector<BodyShape> shapes;
  std::vector<PersonDef> people;
  std::vector<Wall> walls;
  std::vector<geometry::NavigationField> targets;  // desired-direction fields
  PeriodicBox periodic;
  FloorSlope slope;
  int threads = 1;  // worker threads for the force computation (results do not depend on it)
  ComputeDevice device = ComputeDevice::kCpu;  // nor on this
};

}  // namespace crowdrecon::engine
