// The run loop (scenario/run_loop.hpp): the engine step and its systems, in
// order, each timed; a system can stop the run; systems' states round-trip.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/run_loop.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::scenario {
namespace {

// Records what it is called for into a shared log.
class Recorder : public RunSystem {
 public:
  Recorder(std::string name, std::vector<std::string>& log) : name_(std::move(name)), log_(log) {}
  std::string_view name() const override { return name_; }
  bool acts_every_step() const override { return true; }
  void BeforeStep(engine::Simulation& sim) override { log_.push_back(name_ + ":before@" + std::to_string(sim.step_count())); }
  void AfterStep(engine::Simulation& sim) override { log_.push_back(name_ + ":after@" + std::to_string(sim.step_count())); }
  void AtFrame(FrameContext& c) override {
    log_.push_back(name_ + ":frame" + std::to_string(c.frame));
    ++frames_;
    if (stop_at_ == c.frame) c.stop = true;
    if (event_at_ == c.frame) {
      Event e;
      e.kind = "test";
      c.write_event(e);
    }
  }
  std::string SaveState() const override { return std::to_string(frames_); }
  void LoadState(const std::string& state) override { frames_ = std::stoi(state); }

  int frames_ = 0;
  std::int64_t stop_at_ = -1, event_at_ = -1;

 private:
  std::string name_;
  std::vector<std::string>& log_;
};

RunLoop::Options LoopOptions(std::vector<std::string>& log, int steps_per_frame) {
  RunLoop::Options o;
  o.steps_per_frame = steps_per_frame;
  o.step = [&log](engine::Simulation& sim) {
    sim.Step();
    log.push_back("step" + std::to_string(sim.step_count()));
  };
  o.write_event = [&log](const Event& e, std::int64_t frame) { log.push_back("event " + e.kind + " at " + std::to_string(frame)); };
  return o;
}

TEST(RunLoop, SystemsRunAroundEveryStepAndAtEveryFrameInOrder) {
  engine::Simulation sim(engine::testing::RandomGas(3, 1.0, 1, true));
  std::vector<std::string> log;
  RunLoop loop(sim, LoopOptions(log, 2));
  loop.Add(std::make_unique<Recorder>("a", log));
  loop.Add(std::make_unique<Recorder>("b", log));
  loop.Run(0, 2);
  const std::vector<std::string> expected = {
      "a:before@0", "b:before@0", "step1", "a:after@1", "b:after@1",
      "a:before@1", "b:before@1", "step2", "a:after@2", "b:after@2", "a:frame1", "b:frame1",
      "a:before@2", "b:before@2", "step3", "a:after@3", "b:after@3",
      "a:before@3", "b:before@3", "step4", "a:after@4", "b:after@4", "a:frame2", "b:frame2"};
  EXPECT_EQ(log, expected);
  EXPECT_EQ(loop.summary().last_frame, 2);
  EXPECT_FALSE(loop.summary().stopped);
  ASSERT_EQ(loop.summary().system_s.size(), 2u);
  EXPECT_EQ(loop.summary().system_s[0].first, "a");
  EXPECT_GE(loop.summary().system_s[0].second, 0.0);
  EXPECT_GT(loop.summary().engine_s, 0.0);
  EXPECT_NE(loop.summary().BriefReport().find("engine "), std::string::npos);
}

TEST(RunLoop, ASystemStopsTheRunAndWritesEventsAtItsFrame) {
  engine::Simulation sim(engine::testing::RandomGas(3, 1.0, 1, true));
  std::vector<std::string> log;
  RunLoop loop(sim, LoopOptions(log, 1));
  auto recorder = std::make_unique<Recorder>("a", log);
  recorder->stop_at_ = 3;
  recorder->event_at_ = 2;
  loop.Add(std::move(recorder));
  loop.Run(0, 10);
  EXPECT_TRUE(loop.summary().stopped);
  EXPECT_EQ(loop.summary().last_frame, 3);
  EXPECT_EQ(sim.step_count(), 3u);
  EXPECT_NE(std::find(log.begin(), log.end(), "event test at 2"), log.end());
  // A stop asked at the last frame is the end of the run, not an interruption.
  std::vector<std::string> log2;
  RunLoop last(sim, LoopOptions(log2, 1));
  auto at_end = std::make_unique<Recorder>("a", log2);
  at_end->stop_at_ = 5;
  last.Add(std::move(at_end));
  last.Run(3, 5);
  EXPECT_FALSE(last.summary().stopped);
  EXPECT_EQ(last.summary().last_frame, 5);
}

TEST(RunLoop, SystemStatesRoundTripAndAForeignOneIsRefused) {
  engine::Simulation sim(engine::testing::RandomGas(3, 1.0, 1, true));
  std::vector<std::string> log;
  RunLoop loop(sim, LoopOptions(log, 1));
  loop.Add(std::make_unique<Recorder>("a", log));
  loop.Run(0, 4);
  const auto states = loop.SaveStates();
  ASSERT_EQ(states.size(), 1u);
  EXPECT_EQ(states[0], (std::pair<std::string, std::string>{"a", "4"}));

  RunLoop again(sim, LoopOptions(log, 1));
  auto fresh = std::make_unique<Recorder>("a", log);
  Recorder* fresh_ptr = fresh.get();
  again.Add(std::move(fresh));
  again.LoadStates(states);
  EXPECT_EQ(fresh_ptr->frames_, 4);
  EXPECT_THROW(again.LoadStates({{"inflow", "x"}}), InputError);
}

}  // namespace
}  // namespace crowdrecon::scenario
