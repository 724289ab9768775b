// Runs that stop when their regime has settled (scenario/settle.hpp): the
// criteria on hand-made frames of a crowd that freezes, of lanes, of one
// direction stalled while the other walks (never settles), of a jam whose
// force network still changes (never settles), and a state saved and loaded
// half-way that decides exactly as an uninterrupted detector.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/scenario/settle.hpp"

namespace crowdrecon::scenario {
namespace settle_tests {

// A periodic 12 m x 3 m hallway with `n` people in two groups (the first
// `n_exit` walk to +x, the rest to -x) at speeds given per group and time.
struct Crowd {
  std::size_t n = 40, n_exit = 28;
  PeriodicBox box;
  std::vector<std::uint32_t> group;
  std::vector<Vec2> position, velocity, direction;
  std::vector<double> load;
  std::vector<char> present;

  Crowd() {
    box.x = true;
    box.max_m = {12.0, 3.0};
    for (std::size_t i = 0; i < n; ++i) {
      const bool exit = i < n_exit;
      group.push_back(exit ? 0 : 1);
      position.push_back({0.3 * static_cast<double>(i), 0.2 + 0.07 * static_cast<double>(i)});
      velocity.push_back({0.0, 0.0});
      direction.push_back({exit ? 1.0 : -1.0, 0.0});
      load.push_back(200.0 + static_cast<double>(i));
      present.push_back(1);
    }
  }
  // One frame of 0.1 s at speeds v0 (group 0) and v1 (group 1) along the
  // desired directions; loads scaled by `load_factor`.
  std::string Step(SettleDetector& d, double t, double v0, double v1, double load_factor = 1.0) {
    for (std::size_t i = 0; i < n; ++i) {
      const double v = group[i] == 0 ? v0 : v1;
      velocity[i] = direction[i] * v;
      position[i] = position[i] + velocity[i] * 0.1;  // unwrapped: only differences are used
      load[i] = (200.0 + static_cast<double>(i)) * load_factor;
    }
    return d.Add({t, &position, &velocity, &direction, &load, &present});
  }
};

SettleOptions On() {
  SettleOptions o;
  o.enabled = true;
  return o;
}

// Frames every 0.1 s from 0 to `until_s` with speeds from `speeds(t)`;
// returns the time of the stop (or -1) and its reason.
template <typename F>
std::pair<double, std::string> Feed(Crowd& crowd, SettleDetector& d, double from_s, double until_s, F speeds) {
  for (int k = static_cast<int>(std::lround(from_s * 10)); k <= static_cast<int>(std::lround(until_s * 10)); ++k) {
    const double t = k / 10.0;
    const auto [v0, v1, f] = speeds(t);
    const std::string reason = crowd.Step(d, t, v0, v1, f);
    if (!reason.empty()) return {t, reason};
  }
  return {-1.0, ""};
}

struct Speeds {
  double v0, v1, load_factor;
};

TEST(Settle, AFrozenCrowdStopsAfterTheFrozenWindow) {
  Crowd crowd;
  SettleDetector d(On(), crowd.group, {"to_exit", "to_court"}, crowd.box);
  // Walking until 30 s, then frozen (positions, loads constant).
  const auto [t, reason] = Feed(crowd, d, 0.0, 200.0, [](double x) {
    return x < 30.0 - 1e-9 ? Speeds{0.8, 0.6, 1.0} : Speeds{0.0, 0.0, 1.0};
  });
  // Frozen from 30 s; the last moving frame is 29.9 s: the 20 s window of
  // samples (every 1 s from 0 s) without movement is complete at 50 s.
  EXPECT_NEAR(t, 50.0, 1e-9) << reason;
  EXPECT_NE(reason.find("settled frozen at 50.0 s"), std::string::npos) << reason;
  EXPECT_NE(reason.find("every direction frozen at the end"), std::string::npos) << reason;
  EXPECT_NE(reason.find("nobody moved more than 0.0 cm"), std::string::npos) << reason;
}

TEST(Settle, LanesStopAfterTheLanesWindow) {
  Crowd crowd;
  SettleDetector d(On(), crowd.group, {"to_exit", "to_court"}, crowd.box);
  // Both directions walk from the start (0 at t = 0: placed at rest).
  const auto [t, reason] = Feed(crowd, d, 0.0, 200.0, [](double x) {
    return x == 0.0 ? Speeds{0.0, 0.0, 1.0} : Speeds{0.9, 0.7, 1.0};
  });
  // The first frame (rest) falls out of the 60 s window at 60.1 s; samples
  // are evaluated every 1 s: 61 s.
  EXPECT_NEAR(t, 61.0, 1e-9) << reason;
  EXPECT_NE(reason.find("settled in lanes at 61.0 s"), std::string::npos) << reason;
  EXPECT_NE(reason.find("slowest frame: to_court 0.700 m/s"), std::string::npos) << reason;
}

TEST(Settle, LanesAfterALongStallStopOnceTheWindowIsClean) {
  Crowd crowd;
  SettleDetector d(On(), crowd.group, {"to_exit", "to_court"}, crowd.box);
  // The counter-flow stands until 50 s (a long start-up), then walks.
  const auto [t, reason] = Feed(crowd, d, 0.0, 300.0, [](double x) {
    return Speeds{0.9, x < 50.0 - 1e-9 ? 0.01 : 0.7, 1.0};
  });
  EXPECT_NEAR(t, 110.0, 1e-9) << reason;
  EXPECT_NE(reason.find("settled in lanes"), std::string::npos) << reason;
}

TEST(Settle, OneDirectionStalledNeverSettles) {
  Crowd crowd;
  SettleDetector d(On(), crowd.group, {"to_exit", "to_court"}, crowd.box);
  const auto [t, reason] = Feed(crowd, d, 0.0, 300.0, [](double x) {
    return Speeds{0.9, x < 20.0 ? 0.5 : 0.0, 1.0};
  });
  EXPECT_EQ(t, -1.0) << reason;
}

TEST(Settle, AJamWhoseForcesStillChangeNeverSettles) {
  Crowd crowd;
  SettleDetector d(On(), crowd.group, {"to_exit", "to_court"}, crowd.box);
  // Frozen in place from 30 s, but the loads swing by +-30 % with a 7 s period.
  const auto [t, reason] = Feed(crowd, d, 0.0, 200.0, [](double x) {
    return x < 30.0 - 1e-9 ? Speeds{0.8, 0.6, 1.0} : Speeds{0.0, 0.0, 1.0 + 0.3 * std::sin(x)};
  });
  EXPECT_EQ(t, -1.0) << reason;
}

TEST(Settle, SavedStateDecidesAsAnUninterruptedDetector) {
  const auto speeds = [](double x) {
    return x < 30.0 - 1e-9 ? Speeds{0.8, 0.6, 1.0} : Speeds{0.0, 0.0, 1.0};
  };
  Crowd a;
  SettleDetector whole(On(), a.group, {"to_exit", "to_court"}, a.box);
  const auto [t_whole, reason_whole] = Feed(a, whole, 0.0, 200.0, speeds);

  Crowd b;
  SettleDetector first(On(), b.group, {"to_exit", "to_court"}, b.box);
  ASSERT_EQ(Feed(b, first, 0.0, 37.3, speeds).first, -1.0);
  const std::string state = first.SaveState();
  SettleDetector resumed(On(), b.group, {"to_exit", "to_court"}, b.box);
  resumed.LoadState(state);
  const auto [t_resumed, reason_resumed] = Feed(b, resumed, 37.4, 200.0, speeds);
  EXPECT_EQ(t_resumed, t_whole);
  EXPECT_EQ(reason_resumed, reason_whole);

  // Damaged or foreign states are refused.
  SettleDetector other(On(), b.group, {"to_exit", "to_court"}, b.box);
  EXPECT_THROW(other.LoadState(state.substr(0, state.size() - 3)), InputError);
  EXPECT_THROW(other.LoadState("not a state"), InputError);
  std::vector<std::uint32_t> fewer(b.group.begin(), b.group.end() - 1);
  SettleDetector smaller(On(), fewer, {"to_exit", "to_court"}, b.box);
  EXPECT_THROW(smaller.LoadState(state), InputError);
}

TEST(Settle, OptionsAreChecked) {
  SettleOptions o = On();
  std::string error;
  EXPECT_TRUE(o.IsValid(&error));
  o.lanes_window_s = 0.5;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error, "run.stop_when_settled.lanes_window_s = 0.5 s, expected [1, 3600]");
}

}  // namespace settle_tests
}  // namespace crowdrecon::scenario
