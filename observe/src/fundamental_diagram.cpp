#include "crowdrecon/observe/fundamental_diagram.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::observe {

double WeidmannRelation::SpeedAt(double rho) const {
  if (!(rho > 0.0)) return v0_m_per_s;
  if (rho >= rho_max_per_m2) return 0.0;
  return v0_m_per_s * (1.0 - std::exp(-gamma_per_m2 * (1.0 / rho - 1.0 / rho_max_per_m2)));
}

FundamentalDiagram ComputeFundamentalDiagram(const Trajectories& t, const Region& area, double velocity_span_s,
                                             int frame_step, double class_width, const WeidmannRelation& weidmann) {
  if (frame_step < 1) throw InputError("fundamental diagram: frame step " + std::to_string(frame_step) + ", expected >= 1");
  if (!(class_width > 0.0)) throw InputError("fundamental diagram: density class width must be > 0");
  const double area_m2 = area.Area_m2();
  if (!(area_m2 > 0.0)) throw InputError("fundamental diagram: the area " + area.name + " encloses no area");
  const int half_span = std::max(1, static_cast<int>(std::lround(velocity_span_s * t.fps / 2.0)));
  struct Sum {
    std::size_t people = 0, with_v = 0;
    double speed = 0.0;
  };
  std::map<std::int64_t, Sum> frames;
  for (const Track& track : TracksOf(t))
    for (std::size_t k = 0; k < track.frame.size(); ++k) {
      if ((track.frame[k] - t.first_frame) % frame_step != 0 || !area.Contains(track.position_m[k])) continue;
      Sum& s = frames[track.frame[k]];
      ++s.people;
      Vec2 v;
      if (VelocityAt(track, k, half_span, t.fps, t.box, &v)) {
        ++s.with_v;
        s.speed += Length(v);
      }
    }
  FundamentalDiagram fd;
  fd.source = t.source;
  fd.area = area.name;
  std::map<long, DensityClass> classes;
  std::map<long, double> sum_sq;
  for (const auto& [frame, s] : frames) {
    FundamentalDiagramPoint p;
    p.time_s = static_cast<double>(frame) / t.fps;
    p.people = s.people;
    p.density_per_m2 = static_cast<double>(s.people) / area_m2;
    p.speed_m_per_s = s.with_v > 0 ? s.speed / static_cast<double>(s.with_v) : std::numeric_limits<double>::quiet_NaN();
    fd.points.push_back(p);
    if (std::isnan(p.speed_m_per_s)) continue;
    const long k = static_cast<long>(std::floor(p.density_per_m2 / class_width));
    DensityClass& c = classes[k];
    c.density_from = static_cast<double>(k) * class_width;
    c.density_to = c.density_from + class_width;
    ++c.frames;
    c.mean_speed_m_per_s += p.speed_m_per_s;
    sum_sq[k] += p.speed_m_per_s * p.speed_m_per_s;
  }
  double rms = 0.0;
  std::size_t n = 0;
  for (auto& [k, c] : classes) {
    const double f = static_cast<double>(c.frames);
    c.mean_speed_m_per_s /= f;
    c.sd_speed_m_per_s = c.frames > 1 ? std::sqrt(std::max(0.0, (sum_sq[k] - f * c.mean_speed_m_per_s * c.mean_speed_m_per_s) / (f - 1))) : 0.0;
    fd.classes.push_back(c);
    if (c.frames >= 25) {
      const double d = c.mean_speed_m_per_s - weidmann.SpeedAt(0.5 * (c.density_from + c.density_to));
      rms += d * d;
      ++n;
    }
  }
  fd.rms_from_weidmann_m_per_s = n > 0 ? std::sqrt(rms / static_cast<double>(n)) : std::numeric_limits<double>::quiet_NaN();
  return fd;
}

}  // namespace crowdrecon::observe
