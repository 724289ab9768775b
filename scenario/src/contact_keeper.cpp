// Which frames' contacts a run keeps (contact_keeper.hpp).
#include "contact_keeper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/reports/chest_load.hpp"

namespace crowdrecon::scenario::detail {

ContactKeeper::ContactKeeper(const RunSpec& run, std::int64_t checkpoint_every)
    : lean_(run.lean_contacts),
      every_frame_(run.write_contacts && !run.lean_contacts),
      worst_(run.lean_contacts && run.contacts_worst),
      checkpoint_every_(checkpoint_every),
      search_(reports::kDefaultF0_n, reports::SmoothingWindow(reports::kDefaultSmoothing_s, run.output_fps)) {
  if (lean_ && run.contacts_every_s > 0.0) {
    every_frames_ = std::max<std::int64_t>(1, std::llround(run.contacts_every_s * run.output_fps));
    every_text_ = "every " + FormatNumber(double(every_frames_) / run.output_fps) + " s";
  }
}

void ContactKeeper::Decide(runfile::FrameSnapshot& f) {
  f.lean_contacts = lean_;
  if (!lean_) {
    f.with_contacts = every_frame_;
    return;
  }
  const std::int64_t k = f.frame;
  // Superseded worst moments whose successor a periodic checkpoint now holds.
  f.drop_contacts_of.clear();
  if (checkpoint_every_ > 0 && k > 0) {
    const std::int64_t checkpointed = (k - 1) / checkpoint_every_ * checkpoint_every_;
    const auto due = [&](const std::pair<std::int64_t, std::int64_t>& p) { return p.second <= checkpointed; };
    for (const auto& p : pending_)
      if (due(p)) f.drop_contacts_of.push_back(p.first);
    pending_.erase(std::remove_if(pending_.begin(), pending_.end(), due), pending_.end());
  }
  const bool at_rate = every_frames_ > 0 && k % every_frames_ == 0;
  bool worst = false;
  if (worst_) {
    std::vector<double> raw(f.person.size(), 0.0);
    if (f.chest_load_n.size() == f.person.size() && f.lateral_load_n.size() == f.person.size())
      for (std::size_t j = 0; j < raw.size(); ++j) raw[j] = reports::ChestLoad{f.chest_load_n[j], f.lateral_load_n[j]}.load_n();
    worst = search_.Add(f.person, raw);
    if (worst) {
      if (worst_frame_ >= 0 && !worst_kept_anyway_) pending_.emplace_back(worst_frame_, k);
      worst_frame_ = k;
      worst_kept_anyway_ = at_rate;
    }
  }
  f.with_contacts = at_rate || worst;
  f.kept_because = at_rate && worst ? every_text_ + "; worst moment so far"
                   : at_rate         ? every_text_
                   : worst           ? "worst moment so far"
                                     : "";
  // The report's histogram of every contact force.
  reports::ForceHistogram h;
  for (const runfile::Contact& c : f.contacts) h.Add(Length(c.Force()) / reports::kDefaultF0_n);
  f.force_f0_n = reports::kDefaultF0_n;
  f.force_zero = h.zero;
  f.force_total = h.total;
  f.force_bins.clear();
  for (int b = 0; b < reports::ForceHistogram::kBins; ++b)
    if (h.counts[static_cast<std::size_t>(b)] > 0) f.force_bins.emplace_back(b, h.counts[static_cast<std::size_t>(b)]);
}

std::vector<std::int64_t> ContactKeeper::Finish() {
  std::vector<std::int64_t> frames;
  for (const auto& p : pending_) frames.push_back(p.first);
  pending_.clear();
  return frames;
}

std::string ContactKeeper::SaveState() const {
  if (!lean_) return "";
  std::string s = "contacts 1 " + std::to_string(worst_frame_) + " " + (worst_kept_anyway_ ? "1" : "0") + " " +
                  std::to_string(pending_.size());
  for (const auto& [frame, by] : pending_) s += " " + std::to_string(frame) + " " + std::to_string(by);
  return s + "\n" + search_.SaveState();
}

void ContactKeeper::LoadState(const std::string& state) {
  if (!lean_) return;
  if (state.empty())
    throw InputError("the checkpoint holds no state of the kept contacts (written by a run that kept every frame's or "
                     "none: resume with its own scenario)");
  try {
    const std::size_t line = state.find('\n');
    std::istringstream in(state.substr(0, line));
    std::string tag;
    int version = 0, anyway = 0;
    std::size_t pending = 0;
    if (!(in >> tag >> version >> worst_frame_ >> anyway >> pending) || tag != "contacts" || version != 1)
      throw std::invalid_argument("not a state of the kept contacts");
    worst_kept_anyway_ = anyway != 0;
    pending_.clear();
    for (std::size_t k = 0; k < pending; ++k) {
      std::int64_t frame = 0, by = 0;
      if (!(in >> frame >> by)) throw std::invalid_argument("a pending frame is missing");
      pending_.emplace_back(frame, by);
    }
    search_.LoadState(line == std::string::npos ? "" : state.substr(line + 1));
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("the state of the kept contacts is damaged: ") + e.what());
  }
}

}  // namespace crowdrecon::scenario::detail
