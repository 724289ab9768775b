// ANSUR II extract reading, mixed-sex medians, and the thorax-with-arms outline.
#include "crowdrecon/geometry/anthropometry.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"

namespace crowdrecon::geometry {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// sign(v) |v|^p, the superellipse's parametrisation.
double SignedPow(double v, double p) { return std::copysign(std::pow(std::abs(v), p), v); }

// A convex piece of the outline: implicit function (< 0 inside), parametrisation
// t -> point (counter-clockwise for increasing t) and its inverse.
struct Superellipse {
  Vec2 centre;
  double ax = 1, ay = 1, n = 2;
  double Inside(Vec2 p) const {
    const Vec2 d = p - centre;
    return std::pow(std::abs(d.x / ax), n) + std::pow(std::abs(d.y / ay), n) - 1.0;
  }
  Vec2 At(double t) const {
    return centre + Vec2{ax * SignedPow(std::cos(t), 2.0 / n), ay * SignedPow(std::sin(t), 2.0 / n)};
  }
  double ParamOf(Vec2 p) const {
    const Vec2 d = p - centre;
    double t = std::atan2(SignedPow(d.y / ay, n / 2.0), SignedPow(d.x / ax, n / 2.0));
    return t < 0.0 ? t + kTwoPi : t;
  }
};

// The t in [a, b] where f(shape.At(t)) changes sign (f(a) and f(b) differ in sign).
template <typename F>
double Bisect(const Superellipse& shape, const F& f, double a, double b) {
  const bool a_inside = f(shape.At(a)) < 0.0;
  for (int i = 0; i < 60; ++i) {
    const double m = 0.5 * (a + b);
    if ((f(shape.At(m)) < 0.0) == a_inside) a = m; else b = m;
  }
  return 0.5 * (a + b);
}

std::int64_t ParseInteger(const std::string& text, const std::string& where, const std::string& column) {
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0')
    throw InputError(where + ": column " + column + ": \"" + text + "\" is not an integer");
  return v;
}

}  // namespace

std::string ToString(Sex sex) { return sex == Sex::kFemale ? "female" : "male"; }

bool ThoraxDimensions::IsValid(std::string* error) const {
  const std::string problem = [&]() -> std::string {
    const auto bad = [](double v) { return !std::isfinite(v) || v <= 0.0 || v > 2.0; };
    if (bad(chest_breadth_m)) return "chest breadth (" + FormatNumber(chest_breadth_m) + " m) out of (0, 2]";
    if (bad(chest_depth_m)) return "chest depth (" + FormatNumber(chest_depth_m) + " m) out of (0, 2]";
    if (bad(biacromial_breadth_m))
      return "biacromial breadth (" + FormatNumber(biacromial_breadth_m) + " m) out of (0, 2]";
    if (bad(bideltoid_breadth_m))
      return "bideltoid breadth (" + FormatNumber(bideltoid_breadth_m) + " m) out of (0, 2]";
    if (bideltoid_breadth_m <= chest_breadth_m)
      return "bideltoid breadth (" + FormatNumber(bideltoid_breadth_m) +
             " m) is not larger than the chest breadth (" + FormatNumber(chest_breadth_m) +
             " m); expected the arms to stick out";
    return "";
  }();
  if (!problem.empty() && error) *error = problem;
  return problem.empty();
}

bool ThoraxModel::IsValid(std::string* error) const {
  const std::string problem = [&]() -> std::string {
    if (!(superellipse_exponent >= 1.0 && superellipse_exponent <= 10.0))
      return "superellipse exponent (" + FormatNumber(superellipse_exponent) + ") out of [1, 10]";
    if (!(arm_overlap_m > 0.0 && arm_overlap_m < 1.0))
      return "arm overlap (" + FormatNumber(arm_overlap_m) + " m) out of (0, 1)";
    if (!(arm_depth_fraction > 0.0 && arm_depth_fraction <= 1.0))
      return "arm depth fraction (" + FormatNumber(arm_depth_fraction) + ") out of (0, 1]";
    if (samples_per_shape < 16) return "samples per shape (" + std::to_string(samples_per_shape) + ") < 16";
    return "";
  }();
  if (!problem.empty() && error) *error = problem;
  return problem.empty();
}

std::vector<AnsurRecord> ReadAnsurExtract(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw InputError(file.string() + ": cannot open the ANSUR II extract (regenerate it with "
                                     "scripts/make-ansur-extract.py, see docs/bodies.md)");
  CheckInputFile(file, "ANSUR II extract (CSV)");  // a directory opens, and reads as empty
  const std::vector<std::string> expected = {"subjectid", "sex", "chestbreadth", "chestdepth",
                                             "biacromialbreadth", "bideltoidbreadth", "weightkg",
                                             "stature"};
  std::vector<AnsurRecord> records;
  std::string line;
  std::size_t line_no = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    const std::string where = file.string() + ":" + std::to_string(line_no);
    if (!header_seen) {
      if (fields != expected)
        throw InputError(where + ": header \"" + line + "\"; expected subjectid,sex,chestbreadth,"
                                 "chestdepth,biacromialbreadth,bideltoidbreadth,weightkg,stature");
      header_seen = true;
      continue;
    }
    if (fields.size() != expected.size())
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields; expected " +
                       std::to_string(expected.size()));
    AnsurRecord r;
    r.subject_id = ParseInteger(fields[0], where, "subjectid");
    if (fields[1] == "female") r.sex = Sex::kFemale;
    else if (fields[1] == "male") r.sex = Sex::kMale;
    else throw InputError(where + ": column sex: \"" + fields[1] + "\"; expected female or male");
    const auto mm = [&](std::size_t i) {
      return static_cast<double>(ParseInteger(fields[i], where, expected[i])) / 1000.0;
    };
    r.thorax = {mm(2), mm(3), mm(4), mm(5)};
    r.weight_kg = static_cast<double>(ParseInteger(fields[6], where, "weightkg")) / 10.0;  // 0.1 kg units
    r.stature_m = mm(7);
    if (std::string error; !r.thorax.IsValid(&error))
      throw InputError(where + ": subject " + std::to_string(r.subject_id) + ": " + error);
    if (!(r.weight_kg > 0.0)) throw InputError(where + ": weightkg must be positive");
    records.push_back(r);
  }
  if (records.empty()) throw InputError(file.string() + ": no records");
  return records;
}

ThoraxDimensions MedianThoraxDimensions(const std::vector<AnsurRecord>& records, double female_fraction) {
  if (!(female_fraction >= 0.0 && female_fraction <= 1.0))
    throw InputError("female fraction (" + FormatNumber(female_fraction) + ") out of [0, 1]");
  double n_female = 0, n_male = 0;
  for (const AnsurRecord& r : records) (r.sex == Sex::kFemale ? n_female : n_male) += 1.0;
  if ((female_fraction > 0.0 && n_female == 0.0) || (female_fraction < 1.0 && n_male == 0.0))
    throw InputError("the anthropometric records have no " +
                     std::string(n_female == 0.0 ? "female" : "male") +
                     " subject but the female fraction is " + FormatNumber(female_fraction));
  const auto weighted_median = [&](double ThoraxDimensions::*field) {
    std::vector<std::pair<double, double>> values;  // value, weight
    for (const AnsurRecord& r : records) {
      const double w = r.sex == Sex::kFemale ? female_fraction / n_female : (1.0 - female_fraction) / n_male;
      if (w > 0.0) values.push_back({r.thorax.*field, w});
    }
    std::sort(values.begin(), values.end());
    double total = 0.0;
    for (const auto& v : values) total += v.second;
    double cumulative = 0.0;
    for (const auto& v : values) {
      cumulative += v.second;
      if (cumulative >= 0.5 * total) return v.first;
    }
    return values.back().first;
  };
  return {weighted_median(&ThoraxDimensions::chest_breadth_m),
          weighted_median(&ThoraxDimensions::chest_depth_m),
          weighted_median(&ThoraxDimensions::biacromial_breadth_m),
          weighted_median(&ThoraxDimensions::bideltoid_breadth_m)};
}

std::vector<Vec2> ThoraxOutline(const ThoraxDimensions& d, const ThoraxModel& model) {
  if (std::string error; !d.IsValid(&error)) throw GeometryError("thorax outline: " + error);
  if (std::string error; !model.IsValid(&error)) throw GeometryError("thorax model: " + error);

  const Superellipse torso{{0, 0}, d.chest_depth_m / 2, d.chest_breadth_m / 2, model.superellipse_exponent};
  // Arm: from y = B/2 - overlap to y = W/2.
  const double arm_half_width = (d.bideltoid_breadth_m / 2 - (d.chest_breadth_m / 2 - model.arm_overlap_m)) / 2;
  const double arm_half_depth = model.arm_depth_fraction * d.chest_depth_m / 2;
  const double arm_centre_y = d.bideltoid_breadth_m / 2 - arm_half_width;
  const Superellipse arms[2] = {{{0, arm_centre_y}, arm_half_depth, arm_half_width, 2.0},
                                {{0, -arm_centre_y}, arm_half_depth, arm_half_width, 2.0}};

  // Boundary of the union of convex pieces, walked counter-clockwise: follow the
  // torso; where it enters an arm, switch to the arm's boundary at the crossing
  // and follow the arm until it enters the torso again, then switch back. Each
  // arm crosses the torso's boundary twice (both convex, the arm's centre outside
  // the torso), and the front point t = 0 lies outside both arms.
  const double dt = kTwoPi / static_cast<double>(model.samples_per_shape);
  std::vector<Vec2> ring;
  double t = 0.0;
  while (t < kTwoPi - 1e-12) {
    ring.push_back(torso.At(t));
    const double t_next = std::min(t + dt, kTwoPi);
    const Superellipse* entered = nullptr;
    for (const Superellipse& arm : arms)
      if (arm.Inside(torso.At(t_next)) < 0.0) entered = &arm;
    if (!entered) {
      t = t_next;
      continue;
    }
    const Superellipse& arm = *entered;
    const auto in_arm = [&](Vec2 p) { return arm.Inside(p); };
    const auto in_torso = [&](Vec2 p) { return torso.Inside(p); };
    const double t_in = Bisect(torso, in_arm, t, t_next);
    ring.push_back(torso.At(t_in));
    // Along the arm from the entry point to where it dips into the torso.
    double u = arm.ParamOf(torso.At(t_in));
    double u_next = (std::floor(u / dt) + 1.0) * dt;
    for (int guard = 0;; ++guard) {
      if (guard > static_cast<int>(model.samples_per_shape) + 2)
        throw GeometryError("thorax outline: arm does not reach back into the torso");
      if (in_torso(arm.At(u_next)) < 0.0) {
        const double u_out = Bisect(arm, in_torso, u, u_next);
        const Vec2 exit = arm.At(u_out);
        ring.push_back(exit);
        double t_exit = torso.ParamOf(exit);
        if (t_exit < t_in) t_exit += kTwoPi;
        // Continue on the torso at the next grid point after the exit.
        t = (std::floor(t_exit / dt) + 1.0) * dt;
        break;
      }
      ring.push_back(arm.At(u_next));
      u = u_next;
      u_next += dt;
    }
  }
  return ring;
}

}  // namespace crowdrecon::geometry
