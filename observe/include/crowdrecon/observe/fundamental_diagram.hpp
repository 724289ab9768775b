// The fundamental diagram: speed against density in a measurement area, frame
// by frame, as the field measures it (PedPy's classic density and mean speed
// in an area): for every frame, the classic density N/A of the people whose
// position lies in the area, and the mean of their speeds |v| (velocities as
// in observations: a centred difference over the spec's velocity span).
// Compared with Weidmann's speed-density relation (U. Weidmann,
// "Transporttechnik der Fussgänger", 1993; docs/decisions.md, "Facts from
// other sources").
#pragma once

#include <string>
#include <vector>

#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/observe/trajectories.hpp"

namespace crowdrecon::observe {

// v(rho) = v0 [1 - exp(-gamma (1/rho - 1/rho_max))], 0 at and beyond rho_max.
struct WeidmannRelation {
  double v0_m_per_s = 1.34;
  double gamma_per_m2 = 1.913;
  double rho_max_per_m2 = 5.4;
  double SpeedAt(double density_per_m2) const;
};

struct FundamentalDiagramPoint {
  double time_s = 0.0;
  double density_per_m2 = 0.0;
  double speed_m_per_s = 0.0;  // NaN if nobody in the area has a velocity
  std::size_t people = 0;
};

// Means of the points in density classes of equal width.
struct DensityClass {
  double density_from = 0.0, density_to = 0.0;
  std::size_t frames = 0;
  double mean_speed_m_per_s = 0.0, sd_speed_m_per_s = 0.0;
};

struct FundamentalDiagram {
  std::string source;
  std::string area;  // the region's name
  std::vector<FundamentalDiagramPoint> points;  // frames with somebody in the area
  std::vector<DensityClass> classes;
  // Root-mean-square difference of the class means from Weidmann's relation
  // over the classes with at least 25 frames (m/s); NaN if none.
  double rms_from_weidmann_m_per_s = 0.0;
};

// Every `frame_step`-th frame (frames of one person in consecutive frames are
// nearly the same: a step of 5 at 25 fps keeps the figure readable).
FundamentalDiagram ComputeFundamentalDiagram(const Trajectories& t, const Region& area, double velocity_span_s,
                                             int frame_step = 1, double class_width_per_m2 = 0.25,
                                             const WeidmannRelation& weidmann = {});

}  // namespace crowdrecon::observe
