// Which frames' contacts a run keeps (run.contacts; issue 66). `true`: every
// frame's; `false`: none; an object: those of every `every_s` seconds and,
// with `worst`, those of the injury-risk report's worst moment
// (reports/worst_moment.hpp, with the report's default F0 and smoothing), and
// every frame's contact forces in the report's histogram; so that the
// report of a long run draws its force network and force distribution as
// from a run that kept every contact, at a small part of its size.
//
// The worst moment so far changes as the run goes on: the rows of a frame it
// no longer is are dropped once a periodic checkpoint lies at or after the
// frame that superseded it (a run resumed from that checkpoint knows the new
// worst moment, whose rows it keeps), and at the run's end. Which frames are
// pending is part of the checkpoint (SaveState), so that a resumed run keeps
// and drops the same rows as the run made in one go.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/reports/worst_moment.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario::detail {

class ContactKeeper {
 public:
  // `checkpoint_every`: the run's periodic checkpoints, in frames (0: none).
  ContactKeeper(const RunSpec& run, std::int64_t checkpoint_every);
  // Completes snapshot `f` (TakeSnapshot filled it): whether its contacts'
  // rows are written, and for a run that keeps some, why, the rows to drop
  // now and the histogram of its forces.
  void Decide(runfile::FrameSnapshot& f);
  // The rows still to drop at the run's end.
  std::vector<std::int64_t> Finish();
  std::string SaveState() const;
  void LoadState(const std::string& state);

 private:
  bool lean_ = false, every_frame_ = true, worst_ = false;
  std::int64_t every_frames_ = 0;  // a kept frame every so many (0: none at a rate)
  std::string every_text_;         // "every 10 s"
  std::int64_t checkpoint_every_ = 0;
  reports::WorstMomentSearch search_;
  std::int64_t worst_frame_ = -1;
  bool worst_kept_anyway_ = false;  // the worst frame is also a frame kept at the rate
  std::vector<std::pair<std::int64_t, std::int64_t>> pending_;  // (frame to drop, the frame that superseded it)
};

}  // namespace crowdrecon::scenario::detail
