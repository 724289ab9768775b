// The worst moment of a run as the injury-risk report finds it, and the
// histogram of contact forces its figure draws: one source for the report
// (risk.cpp), which reads a run, and the run loop, which keeps the contacts of
// that moment in a run that does not keep every frame's (run.contacts
// {"worst": true}; issue 66), so that the report of such a run draws the same
// force network and the same distribution as from a run with every contact.
//
// The worst moment: each person's chest load (ChestLoad::load_n) smoothed by
// a moving mean over the report's smoothing window (started afresh when the
// person was absent from the frame before), the frame with the most people
// above F0; among frames with as many, the one with the largest smoothed
// load; among those, the earliest.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace crowdrecon::reports {

// The report's defaults (RiskOptions): F0 and the chest load's smoothing.
inline constexpr double kDefaultF0_n = 400.0;
inline constexpr double kDefaultSmoothing_s = 1.0;

// Contact forces |F| / F0, 20 bins per decade from 10^-4 to 10^3 (beyond:
// the first or last bin); forces of zero counted apart.
struct ForceHistogram {
  static constexpr double kLow = -4.0, kHigh = 3.0;
  static constexpr int kPerDecade = 20;
  static constexpr int kBins = static_cast<int>((kHigh - kLow) * kPerDecade);
  std::array<std::uint64_t, kBins> counts{};
  std::uint64_t zero = 0;   // contacts with no force
  std::uint64_t total = 0;
  void Add(double force_over_f0);
  // The bin Add counts force_over_f0 in (-1: zero).
  static int BinOf(double force_over_f0);
  // The fraction of recorded forces above force_over_f0 (at bin edges).
  double FractionAbove(double force_over_f0) const;
  static double UpperEdge(int bin);  // in units of F0
};

// A moving mean over the last `window` samples of one person's load.
class LoadSmoother {
 public:
  explicit LoadSmoother(std::size_t window) : window_(window < 1 ? 1 : window) {}
  double Add(double v);
  void Reset();
  // Its state as text, exactly (a checkpoint), and back.
  std::string Save() const;
  void Load(const std::string& text);

 private:
  std::size_t window_;
  std::deque<double> samples_;
  double sum_ = 0.0;
  std::size_t since_exact_ = 0;
};

// One frame as the search for the worst moment sees it.
struct Moment {
  std::uint32_t above_f0 = 0;  // people whose smoothed load is above F0
  double max_load_n = 0.0;     // the largest smoothed load (0 if none)
};
// Whether `m` is worse than the worst so far (none yet: it is).
bool IsWorse(const Moment& m, const std::optional<Moment>& worst);

// The report's window of smoothing in frames.
std::size_t SmoothingWindow(double smoothing_s, double fps);

// The search over a run's frames in order.
class WorstMomentSearch {
 public:
  WorstMomentSearch(double f0_n, std::size_t window) : f0_n_(f0_n), window_(window) {}
  // A frame: its people (person indices) and their raw chest loads; true if
  // it is the worst moment so far.
  bool Add(const std::vector<std::uint32_t>& person, const std::vector<double>& raw_load_n);
  const std::optional<Moment>& worst() const { return worst_; }
  std::string SaveState() const;
  // Throws std::invalid_argument on text SaveState did not write.
  void LoadState(const std::string& text);

 private:
  double f0_n_;
  std::size_t window_;
  std::vector<LoadSmoother> smooth_;
  std::vector<char> present_, was_present_;
  std::optional<Moment> worst_;
};

}  // namespace crowdrecon::reports
