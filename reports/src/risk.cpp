#include "crowdrecon/reports/risk.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/reports/chest_load.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::reports {

const char* ToString(Zone z) {
  switch (z) {
    case Zone::kSafe: return "safe";
    case Zone::kUncomfortable: return "uncomfortable";
    case Zone::kDanger: return "danger";
  }
  return "?";
}

bool RiskOptions::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& text) {
    if (error) *error = text;
    return false;
  };
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(f0_n)) return fail("F0 = " + FormatNumber(f0_n) + " N, expected a positive load");
  if (!positive(danger_n) || !(danger_n > f0_n))
    return fail("danger load = " + FormatNumber(danger_n) + " N, expected a load above F0 = " + FormatNumber(f0_n) + " N");
  if (!positive(lethal_short_n) || !positive(lethal_short_s) || !positive(lethal_long_n) || !positive(lethal_long_s))
    return fail("tolerance points must be positive loads and times");
  if (!(lethal_short_n > lethal_long_n) || !(lethal_short_s < lethal_long_s))
    return fail("tolerance points (" + FormatNumber(lethal_short_n) + " N, " + FormatNumber(lethal_short_s) + " s) and (" +
                FormatNumber(lethal_long_n) + " N, " + FormatNumber(lethal_long_s) +
                " s): expected the larger load to be tolerated for the shorter time");
  if (!(lethal_long_n > f0_n))
    return fail("the tolerance point " + FormatNumber(lethal_long_n) + " N must lie above F0 = " + FormatNumber(f0_n) + " N");
  if (!(smoothing_s >= 0.0 && smoothing_s <= 60.0))
    return fail("smoothing = " + FormatNumber(smoothing_s) + " s, expected in [0, 60]");
  if (std::string why; validity && !validity->IsValid(&why)) return fail("validity: " + why);
  return true;
}

double RiskOptions::ToleranceExponent() const {
  return std::log(lethal_long_s / lethal_short_s) / std::log(lethal_short_n / lethal_long_n);
}

double RiskOptions::ToleranceTime_s(double load_n) const {
  if (!(load_n > f0_n)) return std::numeric_limits<double>::infinity();
  return lethal_short_s * std::pow(load_n / lethal_short_n, -ToleranceExponent());
}

Zone RiskOptions::ZoneOf(double load_n) const {
  if (load_n > danger_n) return Zone::kDanger;
  if (load_n > f0_n) return Zone::kUncomfortable;
  return Zone::kSafe;
}

namespace {

std::string JsonName(const std::string& json_text) {
  try {
    const nlohmann::json j = nlohmann::json::parse(json_text);
    if (j.contains("name") && j["name"].is_string()) return j["name"].get<std::string>();
    if (j.contains("metadata") && j["metadata"].contains("name") && j["metadata"]["name"].is_string())
      return j["metadata"]["name"].get<std::string>();
  } catch (const std::exception&) {
  }
  return "";
}

// A run that keeps some frames' contacts (contact_keeper.hpp): whether it
// kept the worst moment's, and its force distribution from every frame's
// histogram (binned by |F| / 400 N: the same bins as the rows give where F0
// is 400 N or a whole number of bins from it; else the nearest bins).
void KeptContacts(const runfile::RunFileReader& reader, std::int64_t last_frame, const RiskOptions& options,
                  RunRisk* risk) {
  bool kept = false;
  std::string kept_text;
  for (const auto& [frame, why] : reader.ContactKeptFrames()) {
    if (frame == risk->worst_frame) kept = true;
    if (kept_text.size() < 200) kept_text += (kept_text.empty() ? "" : ", ") + std::to_string(frame);
  }
  risk->has_contacts = kept;
  if (!kept)
    risk->contacts_note = "keeps the contacts of some frames only (frames " + kept_text +
                          "; run.contacts: the run's own worst moment for F0 = " + FormatNumber(kDefaultF0_n) +
                          " N and a smoothing of " + FormatNumber(kDefaultSmoothing_s) + " s), not of this report's "
                          "worst moment (frame " + std::to_string(risk->worst_frame) + ")";
  const std::optional<runfile::ContactForceBins> bins = reader.ContactForces(last_frame, ForceHistogram::kBins);
  if (!bins || bins->total == 0) return;
  const double shift = std::log10(bins->f0_n / options.f0_n) * ForceHistogram::kPerDecade;
  const long whole = std::lround(shift);
  const bool exact = std::abs(shift - double(whole)) < 1e-9;
  ForceHistogram& h = risk->contact_forces;
  h = ForceHistogram{};
  h.zero = bins->zero;
  h.total = bins->total;
  for (int b = 0; b < ForceHistogram::kBins; ++b) {
    const int to = std::clamp(b + static_cast<int>(whole), 0, ForceHistogram::kBins - 1);
    h.counts[static_cast<std::size_t>(to)] += bins->counts[static_cast<std::size_t>(b)];
  }
  risk->contact_rows = bins->total;
  risk->contact_forces_from =
      exact ? "" : "binned by the run as |F| / " + FormatNumber(bins->f0_n) + " N and moved to the nearest bins of F0 = " +
                       FormatNumber(options.f0_n) + " N (within half a bin, 1/40 decade)";
}

}  // namespace

RunRisk AnalyseRunRisk(const std::filesystem::path& run_file, const RiskOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("risk options: " + why);
  if (!runfile::IsRunFile(run_file))
    throw InputError(run_file.string() + ": " + runfile::DescribeNonRunFile(run_file) +
                     ", not a crowdrecon run file; expected the SQLite file of crowdrecon simulate");
  const runfile::RunFileReader reader(run_file);
  RunRisk risk;
  risk.file = run_file;
  risk.fps = reader.fps();
  risk.scenario_name = JsonName(reader.RunValue("scenario"));
  risk.profile = reader.RunValue("profile");
  if (risk.profile.empty()) risk.profile = "paper (run file from before model profiles)";
  risk.venue_name = JsonName(reader.venue_json());
  risk.seed = reader.RunValue("seed");
  const std::vector<runfile::Person> setup = reader.People();
  const PeriodicBox box = reader.periodic_box();
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  if (times.empty()) throw InputError(run_file.string() + ": the run has no frames; expected a run with at least one frame");
  risk.duration_s = times.back().time_s - times.front().time_s;
  std::optional<analysis::PlausibilityPass> validity;
  if (options.validity) validity.emplace(reader, *options.validity);

  const std::size_t n = setup.size();
  risk.people.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    risk.people[i].id = static_cast<std::uint32_t>(i + 1);
    risk.people[i].group = setup[i].group;
  }
  const std::size_t window = SmoothingWindow(options.smoothing_s, risk.fps);
  std::vector<LoadSmoother> smooth(n, LoadSmoother(window));
  std::vector<double> smoothed(n, 0.0), run_above(n, 0.0);
  std::vector<bool> was_present(n, false);
  std::vector<Pose> poses(n);
  std::vector<LoadContact> load_contacts;
  std::vector<runfile::Contact> contacts;
  // Which series (if any) each person's smoothed load goes to.
  std::vector<int> series_slot(n, -1);
  risk.series.resize(options.series_of.size());
  for (std::size_t k = 0; k < options.series_of.size(); ++k)
    if (options.series_of[k] >= 1 && options.series_of[k] <= n) series_slot[options.series_of[k] - 1] = static_cast<int>(k);

  runfile::PersonFrameStream people = reader.PersonFrames(times.back().frame);
  // The chest loads the run loop recorded (table person_load), or, in runs
  // written before it did, computed here from the contacts; the contacts are
  // read where the loads need them or the caller asks for them.
  risk.loads_recorded = reader.HasPersonLoads();
  std::optional<runfile::ContactFrameStream> contact_stream;
  std::int64_t contact_frame = -1;
  bool more_contacts = false;
  if (options.read_contacts || !risk.loads_recorded) {
    contact_stream.emplace(reader.ContactFrames(times.back().frame));
    more_contacts = contact_stream->Next(&contact_frame, &contacts);
  }
  if (!risk.loads_recorded && !more_contacts)
    throw InputError(run_file.string() + ": the run records neither chest loads (table person_load) nor contacts; "
                     "expected a run written by this crowdrecon, or one simulated with \"run\": {\"contacts\": true}");
  risk.has_contacts = more_contacts;
  // A run that keeps some frames' contacts: their rows are those frames'; its
  // overlaps come from the frames' briefs, its force distribution from their
  // histograms (below).
  risk.keeps_some_contacts = reader.KeepsSomeContacts();
  const bool overlaps_from_briefs = reader.HasContactSummary();
  std::optional<runfile::PersonLoadStream> load_stream;
  std::int64_t load_frame = -1;
  std::vector<runfile::PersonLoad> recorded;
  bool more_loads = false;
  if (risk.loads_recorded) {
    load_stream.emplace(reader.PersonLoads(times.back().frame));
    more_loads = load_stream->Next(&load_frame, &recorded);
  }
  runfile::PersonFrame pf;
  double previous_time = times.front().time_s;
  std::size_t done = 0;
  std::size_t time_index = 0;
  std::optional<Moment> worst_moment;  // (worst_moment.hpp: the run loop finds the same frame)
  while (people.Next(&pf)) {
    while (time_index < times.size() && times[time_index].frame < pf.frame) ++time_index;
    const double t = time_index < times.size() && times[time_index].frame == pf.frame ? times[time_index].time_s
                                                                                        : previous_time;
    const double dt = std::max(0.0, t - previous_time);
    previous_time = t;
    for (Pose& p : poses) p.present = false;
    if (validity) validity->AddPeople(pf);
    for (std::size_t k = 0; k < pf.person.size(); ++k) {
      const std::uint32_t i = pf.person[k];
      if (i >= n) throw InputError(run_file.string() + ": frame " + std::to_string(pf.frame) + " has person id " +
                                   std::to_string(std::uint64_t{i} + 1) + " not in table person (the run file is damaged)");
      poses[i] = {pf.position_m[k], pf.angle_rad[k], true};
    }
    load_contacts.clear();
    if (more_contacts && contact_frame < pf.frame)
      throw InputError(run_file.string() + ": table contact has rows of frame " + std::to_string(contact_frame) +
                       ", which has no people (the run file is damaged)");
    const bool have_contacts = more_contacts && contact_frame == pf.frame;
    FrameRisk fr;
    fr.frame = pf.frame;
    fr.time_s = t;
    if (have_contacts) {
      if (validity && !overlaps_from_briefs) validity->AddContacts(pf.frame, contacts);
      for (const runfile::Contact& c : contacts) {
        const Vec2 f = c.Force();
        load_contacts.push_back({c.a, c.b, c.wall, c.point_m, f});
        if (!risk.keeps_some_contacts) risk.contact_forces.Add(Length(f) / options.f0_n);
      }
      fr.contacts = static_cast<std::uint32_t>(contacts.size());
      if (!risk.keeps_some_contacts) risk.contact_rows += contacts.size();
    }
    std::vector<ChestLoad> loads;
    if (risk.loads_recorded) {
      loads.assign(n, ChestLoad{});
      if (more_loads && load_frame < pf.frame)
        throw InputError(run_file.string() + ": table person_load has rows of frame " + std::to_string(load_frame) +
                         ", which has no people (the run file is damaged)");
      if (more_loads && load_frame == pf.frame) {
        for (const runfile::PersonLoad& l : recorded) {
          if (l.person >= n || !poses[l.person].present)
            throw InputError(run_file.string() + ": table person_load, frame " + std::to_string(pf.frame) + ": person " +
                             std::to_string(std::uint64_t{l.person} + 1) + " is not in the frame (the run file is damaged)");
          loads[l.person] = {l.chest_n, l.lateral_n};
        }
        more_loads = load_stream->Next(&load_frame, &recorded);
      }
    } else {
      try {
        loads = ChestLoads(poses, load_contacts, box);
      } catch (const InputError& e) {
        throw InputError(run_file.string() + ": frame " + std::to_string(pf.frame) + ": " + e.what());
      }
    }
    for (std::size_t i = 0; i < n; ++i)
      if (!poses[i].present && was_present[i]) {  // left, or not here this frame
        smooth[i].Reset();
        smoothed[i] = 0.0;
        run_above[i] = 0.0;
        was_present[i] = false;
      }
    for (std::size_t k = 0; k < pf.person.size(); ++k) {
      const std::uint32_t i = pf.person[k];
      PersonRisk& pr = risk.people[i];
      const double raw = loads[i].load_n();
      const double s = smooth[i].Add(raw);
      smoothed[i] = s;
      was_present[i] = true;
      if (series_slot[i] >= 0) risk.series[static_cast<std::size_t>(series_slot[i])].push_back({t, s});
      if (std::isnan(pr.first_seen_s)) pr.first_seen_s = t;
      pr.last_seen_s = t;
      if (pf.state[k] == runfile::PersonStatus::kFallen) pr.fell = true;
      pr.max_raw_load_n = std::max(pr.max_raw_load_n, raw);
      if (s > pr.max_load_n) {
        pr.max_load_n = s;
        pr.max_load_time_s = t;
        pr.max_load_position_m = pf.position_m[k];
      }
      // Each sample stands for the interval since the previous frame.
      if (s > options.f0_n) {
        pr.time_above_f0_s += dt;
        run_above[i] += dt;
        pr.longest_above_f0_s = std::max(pr.longest_above_f0_s, run_above[i]);
        pr.dose += dt / options.ToleranceTime_s(s);
        ++fr.above_f0;
      } else {
        run_above[i] = 0.0;
      }
      if (s > options.danger_n) {
        pr.time_above_danger_s += dt;
        ++fr.above_danger;
      }
      fr.max_load_n = std::max(fr.max_load_n, s);
    }
    fr.present = static_cast<std::uint32_t>(pf.person.size());
    const bool worse = IsWorse({fr.above_f0, fr.max_load_n}, worst_moment);
    if (worse) worst_moment = Moment{fr.above_f0, fr.max_load_n};
    risk.frames.push_back(fr);
    if (worse) {
      // worst_frame holds the index into frames while streaming (the frame number at the end)
      risk.worst_frame = static_cast<std::int64_t>(risk.frames.size() - 1);
      risk.worst_contact_forces_n.clear();
      for (const LoadContact& c : load_contacts) risk.worst_contact_forces_n.push_back(Length(c.force_on_a_n));
      risk.worst_person_loads_n.clear();
      risk.worst_person = 0;
      for (std::size_t k = 0; k < pf.person.size(); ++k) {
        const std::uint32_t i = pf.person[k];
        risk.worst_person_loads_n.push_back(smoothed[i]);
        if (risk.worst_person == 0 || smoothed[i] > smoothed[static_cast<std::size_t>(risk.worst_person - 1)]) {
          risk.worst_person = std::int64_t{i} + 1;
          risk.worst_place_m = pf.position_m[k];
        }
      }
    }
    if (have_contacts) more_contacts = contact_stream->Next(&contact_frame, &contacts);
    if (options.progress) options.progress(++done, times.size());
  }
  if (risk.frames.empty()) throw InputError(run_file.string() + ": the run has no people in any frame");
  if (validity) {
    for (; more_contacts && !overlaps_from_briefs; more_contacts = contact_stream->Next(&contact_frame, &contacts))
      validity->AddContacts(contact_frame, contacts);  // rows after the last frame of people, if any
    risk.validity = validity->Finish(reader);
  }
  const FrameRisk& worst = risk.frames[static_cast<std::size_t>(risk.worst_frame)];
  risk.worst_time_s = worst.time_s;
  risk.worst_frame = worst.frame;
  if (risk.keeps_some_contacts && (options.read_contacts || !risk.loads_recorded))
    KeptContacts(reader, times.back().frame, options, &risk);
  // Everyone who appeared: their zone, and the counts.
  std::vector<PersonRisk> appeared;
  for (PersonRisk& pr : risk.people) {
    if (std::isnan(pr.first_seen_s)) continue;
    pr.zone = options.ZoneOf(pr.max_load_n);
    ++risk.counts[static_cast<std::size_t>(pr.zone)];
    if (pr.dose >= 1.0) ++risk.beyond_tolerance;
    if (pr.fell) ++risk.fallen;
    appeared.push_back(pr);
  }
  risk.people = std::move(appeared);
  std::sort(risk.worst_contact_forces_n.begin(), risk.worst_contact_forces_n.end());
  std::sort(risk.worst_person_loads_n.begin(), risk.worst_person_loads_n.end());
  return risk;
}

}  // namespace crowdrecon::reports
