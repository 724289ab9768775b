// The worst moment and the force histogram (worst_moment.hpp).
#include "crowdrecon/reports/worst_moment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace crowdrecon::reports {

int ForceHistogram::BinOf(double force_over_f0) {
  if (!(force_over_f0 > 0.0)) return -1;
  const int bin = static_cast<int>(std::floor((std::log10(force_over_f0) - kLow) * kPerDecade));
  return std::clamp(bin, 0, kBins - 1);
}

void ForceHistogram::Add(double force_over_f0) {
  ++total;
  const int bin = BinOf(force_over_f0);
  if (bin < 0) ++zero;
  else ++counts[static_cast<std::size_t>(bin)];
}

double ForceHistogram::UpperEdge(int bin) { return std::pow(10.0, kLow + double(bin + 1) / kPerDecade); }

double ForceHistogram::FractionAbove(double force_over_f0) const {
  if (total == 0) return 0.0;
  std::uint64_t above = 0;
  for (int b = 0; b < kBins; ++b)
    if (UpperEdge(b) > force_over_f0 * (1.0 + 1e-12)) above += counts[static_cast<std::size_t>(b)];
  return double(above) / double(total);
}

double LoadSmoother::Add(double v) {
  samples_.push_back(v);
  sum_ += v;
  if (samples_.size() > window_) {
    sum_ -= samples_.front();
    samples_.pop_front();
  }
  // Re-add from scratch now and then: no drift from round-off.
  if (++since_exact_ >= 4096) {
    sum_ = 0.0;
    for (double s : samples_) sum_ += s;
    since_exact_ = 0;
  }
  return std::max(0.0, sum_ / double(samples_.size()));
}

void LoadSmoother::Reset() {
  samples_.clear();
  sum_ = 0.0;
}

namespace {
std::string Exact(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%a", v);
  return text;
}
double ReadExact(std::istream& in) {
  std::string word;
  if (!(in >> word)) throw std::invalid_argument("a number is missing");
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  if (*end != '\0') throw std::invalid_argument("not a number: " + word);
  return v;
}
std::uint64_t ReadCount(std::istream& in) {
  std::uint64_t v = 0;
  if (!(in >> v)) throw std::invalid_argument("a count is missing");
  return v;
}
}  // namespace

std::string LoadSmoother::Save() const {
  std::string s = std::to_string(since_exact_) + " " + Exact(sum_) + " " + std::to_string(samples_.size());
  for (const double v : samples_) s += " " + Exact(v);
  return s;
}

void LoadSmoother::Load(const std::string& text) {
  std::istringstream in(text);
  since_exact_ = ReadCount(in);
  sum_ = ReadExact(in);
  const std::uint64_t n = ReadCount(in);
  if (n > window_) throw std::invalid_argument("more samples than the window holds");
  samples_.clear();
  for (std::uint64_t k = 0; k < n; ++k) samples_.push_back(ReadExact(in));
}

bool IsWorse(const Moment& m, const std::optional<Moment>& worst) {
  return !worst || m.above_f0 > worst->above_f0 || (m.above_f0 == worst->above_f0 && m.max_load_n > worst->max_load_n);
}

std::size_t SmoothingWindow(double smoothing_s, double fps) {
  return static_cast<std::size_t>(std::lround(smoothing_s * fps));
}

bool WorstMomentSearch::Add(const std::vector<std::uint32_t>& person, const std::vector<double>& raw_load_n) {
  std::uint32_t top = 0;
  for (const std::uint32_t i : person) top = std::max(top, i + 1);
  if (top > smooth_.size()) {
    smooth_.resize(top, LoadSmoother(window_));
    present_.resize(top, 0);
    was_present_.resize(top, 0);
  }
  std::fill(present_.begin(), present_.end(), 0);
  for (const std::uint32_t i : person) present_[i] = 1;
  for (std::size_t i = 0; i < smooth_.size(); ++i)
    if (!present_[i] && was_present_[i]) {  // left, or not here this frame
      smooth_[i].Reset();
      was_present_[i] = 0;
    }
  Moment m;
  for (std::size_t k = 0; k < person.size(); ++k) {
    const double s = smooth_[person[k]].Add(raw_load_n[k]);
    was_present_[person[k]] = 1;
    if (s > f0_n_) ++m.above_f0;
    m.max_load_n = std::max(m.max_load_n, s);
  }
  if (!IsWorse(m, worst_)) return false;
  worst_ = m;
  return true;
}

std::string WorstMomentSearch::SaveState() const {
  std::string s = "worst-moment 1 " + std::to_string(smooth_.size()) + " ";
  s += worst_ ? "1 " + std::to_string(worst_->above_f0) + " " + Exact(worst_->max_load_n) : std::string("0 0 0");
  s += "\n";
  for (std::size_t i = 0; i < smooth_.size(); ++i)
    if (was_present_[i]) s += std::to_string(i) + " " + smooth_[i].Save() + "\n";
  return s;
}

void WorstMomentSearch::LoadState(const std::string& text) {
  std::istringstream in(text);
  std::string head, line;
  std::getline(in, head);
  std::istringstream h(head);
  std::string tag;
  if (!(h >> tag) || tag != "worst-moment" || ReadCount(h) != 1) throw std::invalid_argument("not a worst-moment state");
  const std::uint64_t people = ReadCount(h);
  if (people > (std::uint64_t{1} << 31)) throw std::invalid_argument("too many people");
  const bool has_worst = ReadCount(h) != 0;
  const std::uint64_t above = ReadCount(h);
  const double max_load = ReadExact(h);
  smooth_.assign(static_cast<std::size_t>(people), LoadSmoother(window_));
  present_.assign(static_cast<std::size_t>(people), 0);
  was_present_.assign(static_cast<std::size_t>(people), 0);
  worst_.reset();
  if (has_worst) worst_ = Moment{static_cast<std::uint32_t>(above), max_load};
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream l(line);
    const std::uint64_t i = ReadCount(l);
    if (i >= people) throw std::invalid_argument("a person beyond the state's people");
    std::string rest;
    std::getline(l, rest);
    smooth_[static_cast<std::size_t>(i)].Load(rest);
    was_present_[static_cast<std::size_t>(i)] = 1;
  }
}

}  // namespace crowdrecon::reports
