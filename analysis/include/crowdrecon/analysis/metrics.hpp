// Per-frame measurements of a crowd, as plain functions of positions, groups
// and a periodic box (common/periodic_box.hpp): crossings of a measurement line and the lane order
// parameter. Used by AnalyzeRun (run_analysis.hpp) on every frame of a run and
// by the tests on hand-made configurations. Definitions: docs/analysis.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::analysis {

// A measurement line (as in PedPy): the segment from a to b.
struct MeasurementLine {
  Vec2 a_m, b_m;
  double length_m() const { return Length(b_m - a_m); }
};

// How a person's step from `from_m` to `to_m` (consecutive frames) crosses the
// line: +1 along `forward` (the side of the line `forward` points to), -1
// against it, 0 if it does not cross.
//
// The step is taken as the straight path from `from_m` over the minimum-image
// displacement, so a person wrapped across a periodic seam moves a few
// centimetres, not the length of the box; that path is tested against the line
// and its periodic images shifted by one period either way (a step is much
// shorter than half a period, so no farther image can be reached). A step that
// ends exactly on the line counts; one that starts on it does not, so a person
// standing on the line is counted once, when they leave its back side.
// `fraction` (optional) receives where along the step, in [0, 1], the line
// was crossed (the last crossing counted, if several): the passage time is
// then interpolated within the frame interval.
int CrossingDirection(const MeasurementLine& line, Vec2 forward, Vec2 from_m, Vec2 to_m,
                      const PeriodicBox& box, double* fraction = nullptr);

// Lane order parameter after Rex and Löwen, Phys. Rev. E 75, 051402 (2007):
// for each person j, n_same and n_other count the people of j's own group and
// of other groups whose centres lie in a band around j, at most
// `band_half_width_m` across the flow axis and `band_half_length_m` along it
// (minimum-image distances in a periodic box); then
//   phi_j = ((n_same - n_other) / (n_same + n_other))^2   in [0, 1],
// and the order parameter is the mean of phi_j over the people whose band holds
// anyone. phi = 1 for perfectly separated lanes; for a random mixture with a
// fraction p of one's own group and n neighbours, E[phi_j] = (2p - 1)^2 +
// 4 p (1 - p) / n (1/n for two equal groups), so mixing is not 0 but small.
struct LaneOrderOptions {
  // Half-width (m) of the band across the flow: a person belongs to j's lane
  // if their centre is within half a body width (~0.5 m shoulder breadth of the
  // paper's thorax) of j's line of motion; neighbouring lanes, about one body
  // width apart, fall outside.
  double band_half_width_m = 0.25;
  // Half-length (m) of the band along the flow: about six body depths ahead
  // and behind at high density (~0.3 m each), enough neighbours for a stable
  // fraction while staying well below half the 12 m period of the hallway.
  double band_half_length_m = 2.0;

  bool IsValid(std::string* error) const;
};

struct LaneOrderResult {
  double order = 0.0;             // mean phi_j; NaN if nobody has a neighbour in the band
  std::size_t people_counted = 0;  // people whose band holds at least one other person
};

// `flow_axis` (any length > 0) gives the direction along which lanes run;
// `per_person` (optional) receives phi_j, NaN for people with an empty band.
// O(N^2) in the number of people, which is a few hundred in a hallway.
LaneOrderResult LaneOrder(const std::vector<Vec2>& position_m, const std::vector<std::uint32_t>& group,
                          Vec2 flow_axis, const LaneOrderOptions& options, const PeriodicBox& box,
                          std::vector<double>* per_person = nullptr);

}  // namespace crowdrecon::analysis
