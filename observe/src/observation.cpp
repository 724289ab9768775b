#include "crowdrecon/observe/observation.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "crowdrecon/analysis/metrics.hpp"
#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "series_builder.hpp"

namespace crowdrecon::observe {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kFormat = "crowdrecon-observation";
constexpr const char* kSpecFormat = "crowdrecon-observation-spec";

// Every quantity an observation holds and its unit: the one list the series
// are made from and an observation file is checked against.
constexpr std::pair<const char*, const char*> kQuantityUnits[] = {
    {"speed", "m/s"},         {"mean_velocity", "m/s"},     {"max_speed", "m/s"},   {"share_moving", "1"},
    {"share_still", "1"},     {"counterflow_share", "1"},   {"density", "1/m2"},    {"flow", "1/(m s)"}};

// The unit of `quantity`, or "" if no observation has it.
const char* UnitOf(const std::string& quantity) {
  for (const auto& [q, unit] : kQuantityUnits)
    if (quantity == q) return unit;
  return "";
}

// A bound no observed value reaches (speeds, shares, densities, flows): a
// value beyond it is a damaged or foreign file.
constexpr double kMaxObservedValue = 1e6;
}  // namespace

// --- regions ----------------------------------------------------------------

double Region::Area_m2() const {
  double a = 0.0;
  for (std::size_t i = 0, n = polygon_m.size(); i < n; ++i) a += Cross(polygon_m[i], polygon_m[(i + 1) % n]);
  return std::abs(a) / 2.0;
}

bool Region::Contains(Vec2 p) const {
  bool inside = false;  // even-odd rule (a point on the boundary: either)
  for (std::size_t i = 0, n = polygon_m.size(), j = n - 1; i < n; j = i++) {
    const Vec2 a = polygon_m[i], b = polygon_m[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) inside = !inside;
  }
  return inside;
}

// --- the spec ---------------------------------------------------------------

bool ObservationSpec::IsValid(std::string* error) const {
  const auto bad = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!(std::isfinite(axis.x) && std::isfinite(axis.y)) || !(Length(axis) > 1e-9))
    return bad("axis: [" + FormatNumber(axis.x) + ", " + FormatNumber(axis.y) + "], expected a direction (a non-zero vector)");
  if (regions.empty()) return bad("regions: none, expected at least one region");
  std::set<std::string> names;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const Region& r = regions[i];
    if (r.name.empty() || !names.insert(r.name).second)
      return bad("regions/" + std::to_string(i) + "/name: \"" + r.name + "\", expected a name no other region or line has");
    if (r.polygon_m.size() < 3 || !(r.Area_m2() > 1e-6))
      return bad("regions/" + std::to_string(i) + "/polygon: expected at least 3 points enclosing an area");
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].name.empty() || !names.insert(lines[i].name).second)
      return bad("lines/" + std::to_string(i) + "/name: \"" + lines[i].name + "\", expected a name no other region or line has");
    if (!(lines[i].Length_m() > 1e-6)) return bad("lines/" + std::to_string(i) + ": expected two distinct points");
  }
  if (!(bin_s >= 0.01 && bin_s <= 3600.0)) return bad("bin_s: " + FormatNumber(bin_s) + ", expected a time in [0.01, 3600] s");
  if (!(velocity_span_s >= 0.01 && velocity_span_s <= 10.0))
    return bad("velocity_span_s: " + FormatNumber(velocity_span_s) + ", expected a time in [0.01, 10] s");
  if (!(still_speed_m_per_s >= 0.0 && still_speed_m_per_s <= 2.0))
    return bad("still_speed_m_per_s: " + FormatNumber(still_speed_m_per_s) + ", expected a speed in [0, 2] m/s");
  if (!(person_area_m2 >= 0.01 && person_area_m2 <= 2.0))
    return bad("person_area_m2: " + FormatNumber(person_area_m2) + ", expected an area in [0.01, 2] m2");
  if (!(min_moving_area_m2 >= 0.0 && min_moving_area_m2 <= 1000.0))
    return bad("min_moving_area_m2: " + FormatNumber(min_moving_area_m2) + ", expected an area in [0, 1000] m2");
  return events.IsValid(error);
}

ObservationSpec ParseObservationSpec(const std::string& text, const std::string& source) {
  const JsonDocument doc = JsonDocument::Parse(text, source);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected an object (an observation spec, docs/observations.md)");
  if (root.String("format") != kSpecFormat) root.At("format").Fail(std::string("expected \"") + kSpecFormat + "\"");
  root.Integer("version", 1, 1);
  ObservationSpec spec;
  if (root.Has("axis")) {
    spec.axis = root.At("axis").AsPoint();
    if (!(Length(spec.axis) > 1e-9)) root.At("axis").Fail("expected a direction (a non-zero vector)");
    spec.axis = spec.axis * (1.0 / Length(spec.axis));
  }
  const JsonReader regions = root.At("regions");
  if (!regions.IsArray() || regions.Size() == 0) regions.Fail("expected a list of at least one region");
  for (std::size_t i = 0; i < regions.Size(); ++i) {
    const JsonReader r = regions.Element(i);
    Region region;
    region.name = r.String("name");
    region.polygon_m = r.At("polygon").AsPoints(3);
    for (Vec2 p : region.polygon_m)
      if (std::abs(p.x) > kMaxCoordinate_m || std::abs(p.y) > kMaxCoordinate_m)
        r.At("polygon").Fail("a point beyond +-" + FormatNumber(kMaxCoordinate_m) + " m");
    if (!(region.Area_m2() > 1e-6)) r.At("polygon").Fail("the polygon encloses no area");
    r.Finish();
    spec.regions.push_back(std::move(region));
  }
  if (const auto lines = root.Find("lines")) {
    if (!lines->IsArray()) lines->Fail("expected a list of lines");
    for (std::size_t i = 0; i < lines->Size(); ++i) {
      const JsonReader l = lines->Element(i);
      Line line;
      line.name = l.String("name");
      line.a_m = l.At("a").AsPoint();
      line.b_m = l.At("b").AsPoint();
      if (!(line.Length_m() > 1e-6)) l.Fail("the line's two points are the same; expected two distinct points");
      l.Finish();
      spec.lines.push_back(line);
    }
  }
  spec.bin_s = root.Number("bin_s", spec.bin_s, 0.01, 3600.0);
  spec.velocity_span_s = root.Number("velocity_span_s", spec.velocity_span_s, 0.01, 10.0);
  spec.still_speed_m_per_s = root.Number("still_speed_m_per_s", spec.still_speed_m_per_s, 0.0, 2.0);
  spec.person_area_m2 = root.Number("person_area_m2", spec.person_area_m2, 0.01, 2.0);
  spec.min_moving_area_m2 = root.Number("min_moving_area_m2", spec.min_moving_area_m2, 0.0, 1000.0);
  if (const auto ev = root.Find("events")) {
    spec.events.reference_speed_m_per_s = ev->Number("reference_speed_m_per_s", spec.events.reference_speed_m_per_s, 0.001, 5.0);
    spec.events.threshold_m = ev->Number("threshold_m", spec.events.threshold_m, 0.001, 100.0);
    spec.events.min_stop_s = ev->Number("min_stop_s", spec.events.min_stop_s, 0.0, 3600.0);
    ev->Finish();
  }
  if (const auto notes = root.Find("notes")) (void)notes->Size();  // free text for people
  root.Finish();
  std::string error;
  if (!spec.IsValid(&error)) throw InputError(source + ": " + error);
  return spec;
}

ObservationSpec ReadObservationSpec(const std::filesystem::path& file) {
  return ParseObservationSpec(ReadInputFile(file, "observation spec"), file.string());
}

namespace {

nlohmann::json SpecJson(const ObservationSpec& spec) {
  nlohmann::json j;
  j["format"] = kSpecFormat;
  j["version"] = 1;
  j["axis"] = {spec.axis.x, spec.axis.y};
  j["regions"] = nlohmann::json::array();
  for (const Region& r : spec.regions) {
    nlohmann::json poly = nlohmann::json::array();
    for (Vec2 p : r.polygon_m) poly.push_back({p.x, p.y});
    j["regions"].push_back({{"name", r.name}, {"polygon", poly}});
  }
  j["lines"] = nlohmann::json::array();
  for (const Line& l : spec.lines)
    j["lines"].push_back({{"name", l.name}, {"a", {l.a_m.x, l.a_m.y}}, {"b", {l.b_m.x, l.b_m.y}}});
  j["bin_s"] = spec.bin_s;
  j["velocity_span_s"] = spec.velocity_span_s;
  j["still_speed_m_per_s"] = spec.still_speed_m_per_s;
  j["person_area_m2"] = spec.person_area_m2;
  j["min_moving_area_m2"] = spec.min_moving_area_m2;
  j["events"] = {{"reference_speed_m_per_s", spec.events.reference_speed_m_per_s},
                 {"threshold_m", spec.events.threshold_m},
                 {"min_stop_s", spec.events.min_stop_s}};
  return j;
}

}  // namespace

std::string SpecToJson(const ObservationSpec& spec) { return SpecJson(spec).dump(2); }

// --- series -----------------------------------------------------------------

const Series* Observation::Find(const std::string& quantity, const std::string& where,
                                const std::string& direction) const {
  for (const Series& s : series)
    if (s.quantity == quantity && s.where == where && s.direction == direction) return &s;
  return nullptr;
}

std::vector<double> Observation::BinTimes() const {
  std::vector<double> t(bins);
  for (std::size_t k = 0; k < bins; ++k) t[k] = t0_s + (static_cast<double>(k) + 0.5) * bin_s;
  return t;
}

namespace detail {

SeriesBuilder::SeriesBuilder(const ObservationSpec& spec, double t0_s, std::size_t bins, double sample_area_m2)
    : spec_(spec), t0_s_(t0_s), bins_(bins), growable_(bins == 0), sample_area_m2_(sample_area_m2),
      correlated_(std::max(1.0, spec.person_area_m2 / sample_area_m2)),
      cells_(spec.regions.size(), std::vector<Cell>(bins)), frames_(bins, 0.0),
      fwd_(spec.lines.size(), std::vector<double>(bins, 0.0)), bwd_(spec.lines.size(), std::vector<double>(bins, 0.0)) {}

std::size_t SeriesBuilder::Bin(double t_s) const {
  const double k = std::floor((t_s - t0_s_) / spec_.bin_s + 1e-9);
  const double limit = growable_ ? 1e8 : static_cast<double>(bins_);
  return k >= 0.0 && k < limit ? static_cast<std::size_t>(k) : kNoBin;
}

void SeriesBuilder::Grow(std::size_t b) {
  if (b < bins_) return;
  bins_ = b + 1;
  for (auto& r : cells_) r.resize(bins_);
  frames_.resize(bins_, 0.0);
  for (auto* lines : {&fwd_, &bwd_})
    for (auto& l : *lines) l.resize(bins_, 0.0);
}

void SeriesBuilder::AddSample(std::size_t r, std::size_t b, double v) {
  Grow(b);
  Cell& c = cells_[r][b];
  c.n += 1;
  c.s_all += v;
  c.ss_all += v * v;
  c.top = std::max(c.top, std::abs(v));
  if (v > spec_.still_speed_m_per_s) {
    c.n_fwd += 1;
    c.s_fwd += v;
    c.ss_fwd += v * v;
  } else if (v < -spec_.still_speed_m_per_s) {
    c.n_bwd += 1;
    c.s_bwd -= v;
    c.ss_bwd += v * v;
  }
}

void SeriesBuilder::AddFrame(std::size_t b, const std::vector<double>* counts) {
  Grow(b);
  frames_[b] += 1;
  if (!counts) return;
  for (std::size_t r = 0; r < cells_.size(); ++r) {
    cells_[r][b].count += (*counts)[r];
    cells_[r][b].count_sq += (*counts)[r] * (*counts)[r];
  }
}

void SeriesBuilder::AddCrossing(std::size_t l, std::size_t b, int direction) {
  Grow(b);
  (direction > 0 ? fwd_ : bwd_)[l][b] += 1;
}

void SeriesBuilder::Finish(Observation* obs, bool with_density, bool with_flow, double onset_uncertainty_s) const {
  obs->t0_s = t0_s_;
  obs->bin_s = spec_.bin_s;
  obs->bins = bins_;
  // Standard error of a mean of n samples with sum s and sum of squares ss,
  // counting n_eff independent ones.
  const auto mean_se = [](double n, double s, double ss, double n_eff) {
    const double mean = s / n;
    if (n < 2) return std::pair{mean, std::abs(mean)};
    const double var = std::max(0.0, (ss - s * s / n) / (n - 1));
    return std::pair{mean, std::sqrt(var / std::max(1.0, n_eff))};
  };
  // A share p of n_eff independent samples: the binomial error with a
  // continuity term, so that 0 of 10 is not known exactly.
  const auto share_se = [](double p, double n_eff) {
    n_eff = std::max(1.0, n_eff);
    return std::sqrt((p * (1 - p) + 0.25 / n_eff) / n_eff);
  };
  for (std::size_t r = 0; r < cells_.size(); ++r) {
    const std::string& where = spec_.regions[r].name;
    const double area = spec_.regions[r].Area_m2();
    const auto series = [&where](const char* quantity, const char* direction) {
      return Series{quantity, where, direction, UnitOf(quantity), {}};
    };
    Series speed_f = series("speed", "forward"), speed_b = series("speed", "backward"), speed_a = series("speed", "all"),
           share_f = series("share_moving", "forward"), share_b = series("share_moving", "backward"),
           still = series("share_still", "all"), counter = series("counterflow_share", "all"),
           mean_v = series("mean_velocity", "all"), density = series("density", "all"), fastest = series("max_speed", "all");
    for (std::size_t b = 0; b < bins_; ++b) {
      const Cell& c = cells_[r][b];
      const double per = std::max(1.0, frames_[b]) * correlated_;  // samples per independent sample
      if (c.n == 0) {
        const SeriesPoint none{kNaN, kNaN, 0.0};
        for (Series* s : {&speed_f, &speed_b, &speed_a, &share_f, &share_b, &still, &counter, &mean_v, &fastest})
          s->points.push_back(none);
      } else {
        const auto speed_of = [&](double n_d, double s_d, double ss_d) {
          const double moving_area = n_d / std::max(1.0, frames_[b]) * sample_area_m2_;
          if (n_d == 0 || moving_area < spec_.min_moving_area_m2) return SeriesPoint{0.0, spec_.still_speed_m_per_s, n_d};
          const auto [m, se] = mean_se(n_d, s_d, ss_d, n_d / per);
          return SeriesPoint{m, se, n_d};
        };
        speed_f.points.push_back(speed_of(c.n_fwd, c.s_fwd, c.ss_fwd));
        speed_b.points.push_back(speed_of(c.n_bwd, c.s_bwd, c.ss_bwd));
        speed_a.points.push_back(speed_of(c.n_fwd + c.n_bwd, c.s_fwd + c.s_bwd, c.ss_fwd + c.ss_bwd));
        const double n_eff = c.n / per;
        const double pf = c.n_fwd / c.n, pb = c.n_bwd / c.n, ps = 1.0 - pf - pb;
        share_f.points.push_back({pf, share_se(pf, n_eff), c.n});
        share_b.points.push_back({pb, share_se(pb, n_eff), c.n});
        still.points.push_back({ps, share_se(ps, n_eff), c.n});
        const double movers = c.n_fwd + c.n_bwd;
        if (movers > 0) {
          const double q = c.n_bwd / movers;
          counter.points.push_back({q, share_se(q, movers / per), movers});
        } else {
          counter.points.push_back({kNaN, kNaN, 0.0});
        }
        const auto [m, se] = mean_se(c.n, c.s_all, c.ss_all, n_eff);
        mean_v.points.push_back({m, se, c.n});
        // The fastest sample. A maximum has no standard error; its
        // uncertainty is the spec's speed resolution, the still speed (a
        // calibration adds the seeds' spread).
        fastest.points.push_back({c.top, spec_.still_speed_m_per_s, c.n});
      }
      if (with_density) {
        if (frames_[b] == 0) {
          density.points.push_back({kNaN, kNaN, 0.0});
        } else {
          // Classic density: the mean count over the bin's frames; its
          // error, the spread of the counts over the frames and a count's
          // rounding (1/12 person^2).
          const double f = frames_[b];
          const double mean = c.count / f;
          const double var = f > 1 ? std::max(0.0, (c.count_sq - c.count * c.count / f) / (f - 1)) : 0.0;
          density.points.push_back({mean / area, std::sqrt(var / f + 1.0 / 12.0) / area, f});
        }
      }
    }
    std::vector<Series*> list = {&speed_f, &speed_b, &speed_a, &share_f, &share_b, &still, &counter, &mean_v, &fastest};
    if (with_density) list.push_back(&density);
    for (Series* s : list) obs->series.push_back(std::move(*s));
  }
  if (with_flow) {
    for (std::size_t l = 0; l < fwd_.size(); ++l) {
      const double scale = 1.0 / (spec_.bin_s * spec_.lines[l].Length_m());
      for (int d = 0; d < 2; ++d) {
        Series s{"flow", spec_.lines[l].name, d == 0 ? "forward" : "backward", UnitOf("flow"), {}};
        for (std::size_t b = 0; b < bins_; ++b) {
          if (frames_[b] == 0) {
            s.points.push_back({kNaN, kNaN, 0.0});
            continue;
          }
          const double c = (d == 0 ? fwd_ : bwd_)[l][b];
          // Poisson error of the count (at least that of one crossing).
          s.points.push_back({c * scale, std::sqrt(std::max(c, 1.0)) * scale, c});
        }
        obs->series.push_back(std::move(s));
      }
    }
  }
  // Events from the speed series of every region and direction.
  std::vector<double> starts(bins_);
  for (std::size_t b = 0; b < bins_; ++b) starts[b] = t0_s_ + static_cast<double>(b) * spec_.bin_s;
  for (const Region& region : spec_.regions)
    for (const char* dir : {"forward", "backward", "all"}) {
      const Series* s = obs->Find("speed", region.name, dir);
      std::vector<double> v(bins_);
      for (std::size_t b = 0; b < bins_; ++b) v[b] = s->points[b].value;
      for (Event& e : DetectEvents(starts, v, spec_.bin_s, onset_uncertainty_s, spec_.events, region.name, dir))
        obs->events.push_back(std::move(e));
    }
}

}  // namespace detail

// --- from trajectories ----------------------------------------------------------

Observation ObserveTrajectories(const Trajectories& t, const ObservationSpec& spec) {
  std::string error;
  if (!spec.IsValid(&error)) throw InputError("observation spec: " + error);
  Observation obs;
  obs.source_file = t.source;
  // Trajectories built in memory (tests) have no file to checksum.
  obs.source_sha256 = std::filesystem::is_regular_file(t.source) ? Sha256OfFile(t.source) : "";
  obs.source_format = t.format.empty() ? "petrack" : t.format;
  obs.method = "trajectories";
  obs.spec = spec;
  obs.spec.axis = spec.axis * (1.0 / Length(spec.axis));
  obs.notes = t.notes;
  const Vec2 axis = obs.spec.axis;
  const int half_span = std::max(1, static_cast<int>(std::lround(spec.velocity_span_s * t.fps / 2.0)));
  nlohmann::json options = {{"fps", t.fps}, {"velocity_half_span_frames", half_span},
                            {"velocity_span_s", 2.0 * half_span / t.fps},
                            {"periodic", t.box.any()}};
  obs.method_options_json = options.dump();

  const double t0 = static_cast<double>(t.first_frame) / t.fps;
  const double duration = static_cast<double>(t.last_frame - t.first_frame + 1) / t.fps;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(duration / spec.bin_s - 1e-9));
  detail::SeriesBuilder builder(obs.spec, t0, std::max<std::size_t>(1, bins), spec.person_area_m2);

  // People per region and frame (classic density).
  const std::size_t frames = static_cast<std::size_t>(t.last_frame - t.first_frame + 1);
  std::vector<std::vector<double>> counts(frames, std::vector<double>(spec.regions.size(), 0.0));
  std::vector<bool> seen(frames, false);
  std::vector<analysis::MeasurementLine> lines;
  for (const Line& l : spec.lines) lines.push_back({l.a_m, l.b_m});

  for (const Track& track : TracksOf(t)) {
    for (std::size_t k = 0; k < track.frame.size(); ++k) {
      const std::size_t fi = static_cast<std::size_t>(track.frame[k] - t.first_frame);
      seen[fi] = true;
      const double time = static_cast<double>(track.frame[k]) / t.fps;
      const std::size_t b = builder.Bin(time);
      Vec2 v;
      const bool has_v = VelocityAt(track, k, half_span, t.fps, t.box, &v);
      for (std::size_t r = 0; r < spec.regions.size(); ++r) {
        if (!spec.regions[r].Contains(track.position_m[k])) continue;
        counts[fi][r] += 1;
        if (has_v && b != detail::SeriesBuilder::kNoBin) builder.AddSample(r, b, Dot(v, axis));
      }
      // Crossings between consecutive frames.
      if (k > 0 && track.frame[k] - track.frame[k - 1] == 1)
        for (std::size_t l = 0; l < lines.size(); ++l) {
          double fraction = 0.0;
          const int dir = analysis::CrossingDirection(lines[l], axis, track.position_m[k - 1], track.position_m[k], t.box,
                                                      &fraction);
          if (dir == 0) continue;
          const std::size_t cb = builder.Bin((static_cast<double>(track.frame[k - 1]) + fraction) / t.fps);
          if (cb != detail::SeriesBuilder::kNoBin) builder.AddCrossing(l, cb, dir);
        }
    }
  }
  for (std::size_t fi = 0; fi < frames; ++fi) {
    if (!seen[fi]) continue;  // a frame with nobody in the file: not observed
    const std::size_t b = builder.Bin(static_cast<double>(t.first_frame + static_cast<std::int64_t>(fi)) / t.fps);
    if (b != detail::SeriesBuilder::kNoBin) builder.AddFrame(b, &counts[fi]);
  }
  // An onset is placed within its bin, and velocities smear it by half their span.
  builder.Finish(&obs, true, true, spec.bin_s + static_cast<double>(half_span) / t.fps);
  return obs;
}

// --- files ------------------------------------------------------------------------

namespace {

std::string CsvNumber(double v) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

nlohmann::json NumberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

std::filesystem::path ObservationCsvPath(const std::filesystem::path& json_file) {
  std::filesystem::path csv = json_file;
  csv.replace_extension(".csv");
  return csv;
}

std::filesystem::path ObservationSeriesPath(const std::filesystem::path& json_file) {
  std::ifstream in(json_file, std::ios::binary);
  if (in) {
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_object() && j.contains("series_file") && j["series_file"].is_object() && j["series_file"].contains("name") &&
        j["series_file"]["name"].is_string())
      return json_file.parent_path() / j["series_file"]["name"].get<std::string>();
  }
  return ObservationCsvPath(json_file);
}

namespace {
constexpr const char* kCsvHeader = "time_s,quantity,where,direction,unit,value,uncertainty,samples";
}

OutputKind ObservationJsonOutput() {
  return JsonOutputKind("an observation (format crowdrecon-observation)", [](const nlohmann::json& j) {
    return j.contains("format") && j["format"] == kFormat;
  });
}

OutputKind ObservationCsvOutput() {
  return {"the series of an observation (CSV)", false,
          [](const std::filesystem::path& file) { return FileStartsWith(file, kCsvHeader); }};
}

std::vector<std::filesystem::path> WriteObservation(const Observation& obs, const std::filesystem::path& json_file) {
  const std::filesystem::path csv_file = ObservationCsvPath(json_file);
  if (csv_file == json_file) throw InputError(json_file.string() + ": the observation file must end in .json");
  std::ostringstream csv;
  csv << kCsvHeader << '\n';
  const std::vector<double> times = obs.BinTimes();
  for (const Series& s : obs.series)
    for (std::size_t b = 0; b < s.points.size(); ++b)
      csv << CsvNumber(times[b]) << ',' << CsvField(s.quantity) << ',' << CsvField(s.where) << ','
          << CsvField(s.direction) << ',' << CsvField(s.unit) << ','
          << CsvNumber(s.points[b].value) << ',' << CsvNumber(s.points[b].uncertainty) << ','
          << CsvNumber(s.points[b].samples) << '\n';
  const std::string csv_text = csv.str();

  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = 1;
  j["source"] = {{"file", obs.source_file},
                 {"sha256", obs.source_sha256},
                 {"format", obs.source_format},
                 {"method", obs.method},
                 {"options", nlohmann::json::parse(obs.method_options_json)}};
  j["spec"] = SpecJson(obs.spec);
  j["time"] = {{"t0_s", obs.t0_s}, {"bin_s", obs.bin_s}, {"bins", obs.bins}};
  j["series_file"] = {{"name", csv_file.filename().string()}, {"sha256", Sha256Hex(csv_text)}};
  j["series"] = nlohmann::json::array();
  for (const Series& s : obs.series)
    j["series"].push_back({{"quantity", s.quantity}, {"where", s.where}, {"direction", s.direction}, {"unit", s.unit}});
  j["events"] = nlohmann::json::array();
  for (const Event& e : obs.events)
    j["events"].push_back({{"kind", e.kind},
                           {"where", e.where},
                           {"direction", e.direction},
                           {"time_s", e.time_s},
                           {"uncertainty_s", e.uncertainty_s},
                           {"end_s", NumberOrNull(e.end_s)},
                           {"censored", e.censored},
                           {"peak_speed_m_per_s", NumberOrNull(e.kind == "surge" ? e.peak_speed_m_per_s : kNaN)},
                           {"rise_time_s", NumberOrNull(e.kind == "surge" ? e.rise_time_s : kNaN)}});
  j["notes"] = obs.notes;
  // Both complete before either replaces a previous observation (a full disk
  // leaves the previous pair whole); the CSV renamed first, so a JSON on disk
  // always names a complete CSV, and its SHA-256 tells a pair apart.
  return WriteFilesAtomically({{csv_file, csv_text}, {json_file, j.dump(2) + "\n"}});
}

Observation ReadObservation(const std::filesystem::path& json_file) {
  const JsonDocument doc = JsonDocument::Load(json_file);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected an observation (docs/observations.md)");
  if (root.String("format") != kFormat) root.At("format").Fail(std::string("expected \"") + kFormat + "\"");
  root.Integer("version", 1, 1);
  Observation obs;
  const JsonReader source = root.At("source");
  obs.source_file = source.String("file");
  obs.source_sha256 = source.String("sha256");
  obs.source_format = source.String("format");
  obs.method = source.Choice("method", {"trajectories", "footage"});
  obs.method_options_json = doc.Json().at("source").at("options").dump();
  (void)source.At("options");
  source.Finish();
  obs.spec = ParseObservationSpec(doc.Json().at("spec").dump(), json_file.string() + ": /spec");
  (void)root.At("spec");
  const JsonReader time = root.At("time");
  obs.t0_s = time.Number("t0_s", -1e9, 1e9);
  obs.bin_s = time.Number("bin_s", 0.01, 3600.0);
  obs.bins = static_cast<std::size_t>(time.Integer("bins", 1, 100'000'000));
  time.Finish();
  const JsonReader series_file = root.At("series_file");
  const std::filesystem::path csv_file = json_file.parent_path() / series_file.String("name");
  const std::string csv_sha = series_file.String("sha256");
  series_file.Finish();
  const JsonReader list = root.At("series");
  std::map<std::tuple<std::string, std::string, std::string>, std::size_t> index;
  for (std::size_t i = 0; i < list.Size(); ++i) {
    const JsonReader s = list.Element(i);
    Series series{s.String("quantity"), s.String("where"), s.String("direction"), s.String("unit"), {}};
    if (const std::string unit = UnitOf(series.quantity); unit.empty())
      s.At("quantity").Fail("unknown quantity \"" + ShortText(series.quantity) +
                            "\"; expected speed, mean_velocity, max_speed, share_moving, share_still, "
                            "counterflow_share, density or flow");
    else if (series.unit != unit)
      s.At("unit").Fail("unit \"" + ShortText(series.unit) + "\" for " + series.quantity + "; expected \"" + unit + "\"");
    series.points.assign(obs.bins, SeriesPoint{kNaN, kNaN, 0.0});
    if (!index.emplace(std::tuple{series.quantity, series.where, series.direction}, i).second)
      s.Fail("a series named twice");
    s.Finish();
    obs.series.push_back(std::move(series));
  }
  const JsonReader events = root.At("events");
  for (std::size_t i = 0; i < events.Size(); ++i) {
    const JsonReader e = events.Element(i);
    Event ev;
    ev.kind = e.Choice("kind", {"stop", "surge"});
    ev.where = e.String("where");
    ev.direction = e.Choice("direction", {"forward", "backward", "all"});
    ev.time_s = e.Number("time_s", -1e9, 1e9);
    ev.uncertainty_s = e.Number("uncertainty_s", 0.0, 1e9);
    const auto number_or_nan = [&](const char* key) {
      const auto v = e.Find(key);
      return !v || doc.Json().at(nlohmann::json::json_pointer(v->path())).is_null() ? kNaN : v->AsNumber(-1e9, 1e9);
    };
    ev.end_s = number_or_nan("end_s");
    ev.censored = e.Bool("censored", false);
    ev.peak_speed_m_per_s = number_or_nan("peak_speed_m_per_s");
    ev.rise_time_s = number_or_nan("rise_time_s");
    if (ev.end_s < ev.time_s)
      e.At("end_s").Fail("the event ends at " + FormatNumber(ev.end_s) + " s, before it begins at " +
                         FormatNumber(ev.time_s) + " s; expected an end after the onset");
    e.Finish();
    obs.events.push_back(std::move(ev));
  }
  if (const auto notes = root.Find("notes"))
    for (std::size_t i = 0; i < notes->Size(); ++i) obs.notes.push_back(notes->Element(i).AsString());
  root.Finish();

  const std::string text = ReadInputFile(csv_file, "observation series (CSV)");
  if (Sha256Hex(text) != csv_sha)
    throw InputError(csv_file.string() + ": its SHA-256 differs from the one " + json_file.string() +
                     " records; expected the series written with it (the CSV was changed or replaced)");
  std::size_t line_no = 0;
  const auto number = [&](const std::string& field, const char* column) {
    if (field.empty()) return kNaN;
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    if (end != field.c_str() + field.size() || !std::isfinite(v))
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": " + column + " \"" + ShortText(field) +
                       "\"; expected a number or nothing");
    return v;
  };
  const std::vector<CsvRecord> records = ParseCsv(text, csv_file.string());
  if (records.size() < 2)
    throw InputError(csv_file.string() + ": no rows of series; expected the header " + kCsvHeader +
                     " and a row per series and bin (an observation's series are never all empty)");
  std::set<std::pair<std::size_t, std::size_t>> seen;  // (series, bin): each once
  for (std::size_t r = 1; r < records.size(); ++r) {  // records[0]: the header
    line_no = records[r].line;
    const std::vector<std::string>& f = records[r].fields;
    if (f.size() != 8)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": " + std::to_string(f.size()) +
                       " fields; expected time_s,quantity,where,direction,unit,value,uncertainty,samples");
    const auto it = index.find({f[1], f[2], f[3]});
    if (it == index.end())
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": series " + f[1] + " " + f[2] + " " + f[3] +
                       " is not listed in " + json_file.string());
    const double t = number(f[0], "time_s");
    const double k = std::round((t - obs.t0_s) / obs.bin_s - 0.5);
    if (!(k >= 0 && k < static_cast<double>(obs.bins)))
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": time_s " + f[0] + " is outside the " +
                       std::to_string(obs.bins) + " bins");
    // The CSV's times are the centres of the JSON's bins (written with %.9g).
    const double centre = obs.t0_s + (k + 0.5) * obs.bin_s;
    if (std::abs(t - centre) > 1e-6 * std::max(1.0, std::abs(centre)))
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": time_s " + f[0] +
                       " is not the centre of a bin (the nearest is " + FormatNumber(centre) + " s with t0_s " +
                       FormatNumber(obs.t0_s) + " and bin_s " + FormatNumber(obs.bin_s) + " of " + json_file.string() +
                       "); expected the times of its bins");
    if (!seen.emplace(it->second, static_cast<std::size_t>(k)).second)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": series " + f[1] + " " + f[2] + " " + f[3] +
                       " at " + f[0] + " s a second time; expected one row per series and bin");
    const SeriesPoint point{number(f[5], "value"), number(f[6], "uncertainty"), number(f[7], "samples")};
    if (std::abs(point.value) > kMaxObservedValue)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": value " + f[5] + " is beyond " +
                       FormatNumber(kMaxObservedValue) + " in magnitude; expected an observed " + f[1] + " in " + f[4]);
    if (point.uncertainty < 0.0 || point.uncertainty > kMaxObservedValue)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": uncertainty " + f[6] +
                       "; expected a number in [0, " + FormatNumber(kMaxObservedValue) + "] or nothing");
    if (point.samples < 0.0)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": samples " + f[7] +
                       "; expected a count of at least 0");
    if (f[4] != obs.series[it->second].unit)
      throw InputError(csv_file.string() + ":" + std::to_string(line_no) + ": unit \"" + ShortText(f[4]) + "\" for " +
                       f[1] + "; " + json_file.string() + " says \"" + obs.series[it->second].unit + "\"");
    obs.series[it->second].points[static_cast<std::size_t>(k)] = point;
  }
  return obs;
}

}  // namespace crowdrecon::observe
