// Running the validation suite (validate.hpp): each test a sweep, each run
// measured as it ends, the experiments measured alike, the criteria judged,
// the report written.
#include "crowdrecon/validate/validate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "crowdrecon/reports/html_page.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"
#include "validation_report.hpp"

namespace crowdrecon::validate {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr const char* kFolderFormat = "crowdrecon-validation-folder";

json ToJson(const Statistics& s) {
  json o = json::object();
  for (const auto& [name, values] : s) {
    json a = json::array();
    for (double v : values) a.push_back(std::isfinite(v) ? json(v) : json(nullptr));
    o[name] = a;
  }
  return o;
}

// The sweep of a test on a profile: the test's scenario, its overrides and
// then the profile's, its cases as variants, its seeds.
json SweepOf(const ValidationTest& test, const Profile& profile, int max_seeds) {
  json set = json::object();
  for (const sweep::Override& o : test.set) set[o.path] = json::parse(o.json);
  for (const sweep::Override& o : profile.set) set[o.path] = json::parse(o.json);
  json variants = json::array();
  for (const Case& c : test.cases) {
    json v = json::object();
    for (const sweep::Override& o : c.set) v[o.path] = json::parse(o.json);
    variants.push_back({{"name", c.name}, {"set", v}});
  }
  json seeds = json::array();
  for (std::size_t i = 0; i < test.seeds.size() && (max_seeds <= 0 || int(i) < max_seeds); ++i) seeds.push_back(test.seeds[i]);
  return {{"format", "crowdrecon-sweep"},
          {"version", 1},
          {"name", test.id + " (" + profile.name + ")"},
          {"scenario", test.scenario.string()},
          {"set", set},
          {"seeds", seeds},
          {"variants", variants},
          {"keep_runs", false}};
}

// The files a sweep reads besides its own text (the scenario, its venue,
// bodies and tables, the cases' venues): every string of the scenario and of
// the sweep that names a file, relative to the file that names it, followed
// into JSON files two levels down. Their content names the runs' folder, so
// that an edited venue is never measured with the runs of the old one.
void DigestInputs(const json& j, const fs::path& base, int depth, std::set<fs::path>* seen, std::string* out) {
  if (j.is_object() || j.is_array()) {
    for (const json& v : j) DigestInputs(v, base, depth, seen, out);
    return;
  }
  if (!j.is_string()) return;
  const std::string& text = j.get_ref<const std::string&>();
  if (text.empty() || text.size() > 4096) return;
  std::error_code ec;
  const fs::path file = fs::path(text).is_absolute() ? fs::path(text) : base / text;
  if (!fs::is_regular_file(file, ec)) return;
  const fs::path key = fs::weakly_canonical(file, ec);
  if (!seen->insert(key).second) return;
  const std::string content = ReadInputFile(file, "input file");
  *out += key.filename().string() + " " + Sha256Hex(content) + "\n";
  if (depth > 0 && file.extension() == ".json") {
    const json inner = json::parse(content, nullptr, false);
    if (!inner.is_discarded()) DigestInputs(inner, file.parent_path(), depth - 1, seen, out);
  }
}

std::string InputsDigest(const json& sweep_json, const fs::path& scenario) {
  std::set<fs::path> seen;
  std::string out;
  DigestInputs(json(scenario.string()), scenario.parent_path(), 2, &seen, &out);
  DigestInputs(sweep_json, scenario.parent_path(), 2, &seen, &out);
  return Sha256Hex(out);
}

// What the report draws of the setup: the first run's walls and start.
json SetupOf(const fs::path& run_file) {
  const runfile::RunFileReader reader(run_file);
  json walls = json::array();
  for (const runfile::Wall& w : reader.Walls()) {
    json pts = json::array();
    for (const Vec2& p : w.points) pts.push_back({p.x, p.y});
    if (w.closed && !w.points.empty()) pts.push_back({w.points.front().x, w.points.front().y});
    walls.push_back(pts);
  }
  json start = json::array();
  const std::vector<std::int64_t> frames = reader.Frames();
  if (!frames.empty()) {
    const runfile::RunFrame f = reader.Frame(frames.front());
    for (const Vec2& p : f.position_m) start.push_back({p.x, p.y});
  }
  return {{"walls", walls}, {"start", start}};
}

struct TestRun {
  std::vector<std::vector<Statistics>> runs;
  json setup;
  double wall_s = 0.0;
  bool interrupted = false;
};

TestRun RunTest(const ValidationTest& test, const Profile& profile, const ValidateOptions& options) {
  const json sweep_json = SweepOf(test, profile, options.seeds);
  const std::string sweep_text = sweep_json.dump(1);
  // The folder is named by the sweep's text, the test's measure, the content
  // of the files the runs read and the build's sources (a sweep's runs are
  // one source fingerprint's: sweep/results.hpp): a changed test, measure,
  // profile or input file, or other sources, is a new sweep, never one
  // refused as "a different sweep" or mixed with other sources' runs; a
  // commit of documents or results reuses the runs (and so does another
  // machine building the same sources).
  const std::string key = Sha256Hex(sweep_text + "\nmeasure " + test.measure_json + "\ninputs " +
                                    InputsDigest(sweep_json, test.scenario) + "\nsources " + sweep::SourceFingerprint())
                              .substr(0, 12);
  const fs::path dir = options.output_dir / "runs" / profile.name / (test.id + "-" + key);
  CreateOutputFolder(dir);
  CreateOutputFolder(dir / "measures");
  const fs::path sweep_file = dir / "sweep.json";
  if (!fs::exists(sweep_file) || ReadInputFile(sweep_file, "validation sweep") != sweep_text)
    WriteFileAtomically(sweep_file, sweep_text);

  sweep::SweepOptions so;
  so.sweep_file = sweep_file;
  so.output_dir = dir / "sweep";
  so.jobs = options.jobs;
  so.show_progress = options.show_progress;
  so.after_run = [&](const sweep::RunPlan& run, const fs::path& run_file, const std::string& status) {
    Statistics s;
    json setup;
    if (status == "complete") {
      s = MeasureRun(run_file, test.measure);
      if (run.index == 0) setup = SetupOf(run_file);
    } else {
      s["completed"] = {0.0};
    }
    json out = {{"run", run.id}, {"status", status}, {"statistics", ToJson(s)}};
    if (!setup.is_null()) out["setup"] = setup;
    WriteFileAtomically(dir / "measures" / (run.id + ".json"), out.dump());
  };
  const sweep::SweepSummary summary = sweep::RunSweep(so);
  TestRun tr;
  tr.interrupted = summary.interrupted;
  if (tr.interrupted) return tr;
  const sweep::SweepSpec spec = sweep::LoadSweep(sweep_file);
  const std::vector<sweep::RunPlan> plans = sweep::ExpandRuns(spec);
  tr.runs.assign(test.cases.size(), {});
  for (const sweep::RunPlan& plan : plans) {
    const fs::path f = dir / "measures" / (plan.id + ".json");
    std::error_code ec;
    if (!fs::is_regular_file(f, ec))
      throw InputError(f.string() + ": the run " + plan.id +
                       " has a row in the sweep's table but no measure (a validation of another build?); remove " +
                       dir.string() + " and run again");
    const json m = json::parse(ReadInputFile(f, "validation measure"));
    tr.runs[plan.variant].push_back(StatisticsFromJson(m.at("statistics").dump(), f.string()));
    if (plan.index == 0 && m.contains("setup")) tr.setup = m["setup"];
  }
  const sweep::ResultsTable table = sweep::ReadResults(dir / "sweep");
  if (const auto column = table.FindColumn("wall_s"))
    for (const auto& row : table.rows)
      if (!row[*column].null && row[*column].numeric) tr.wall_s += row[*column].number;
  return tr;
}

// The experiment measured with the test's measure.
std::optional<Statistics> MeasureData(const ValidationTest& test) {
  if (!test.data) return std::nullopt;
  const DataReference& d = *test.data;
  CheckInputFile(d.trajectories, "the experiment's trajectories of test " + test.id);
  const observe::Trajectories t = observe::ReadTrajectories(d.trajectories, 0.0, d.unit);
  return MeasureTrajectories(t, d.measure);
}

void Say(const ValidateOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

}  // namespace

bool ValidateOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (suite.empty()) return fail("no suite given; expected the suite folder (venues/validation) or a test file");
  if (profiles.empty() || profiles.size() > 2) return fail("expected one or two profiles (--profile)");
  if (output_dir.empty()) return fail("-o: expected the validation's folder");
  if (seeds < 0 || seeds > 1000) return fail("--seeds: expected 0 (each test's own) .. 1000");
  // The report's folder never inside the suite: its files would be read as
  // tests (issue 65: -o SUITE/tests --force wrote results.json among them).
  std::error_code ec;
  const fs::path suite_dir = fs::weakly_canonical(fs::is_directory(suite, ec) ? suite : suite.parent_path(), ec);
  const fs::path out = fs::weakly_canonical(output_dir, ec);
  const auto [s_end, o_end] = std::mismatch(suite_dir.begin(), suite_dir.end(), out.begin(), out.end());
  if (!suite_dir.empty() && s_end == suite_dir.end())
    return fail("-o " + output_dir.string() + ": inside the suite's folder " + suite_dir.string() +
                ", whose files are read as its tests and profiles; choose a folder outside it");
  return true;
}

std::string StatisticsToJson(const Statistics& statistics) { return ToJson(statistics).dump(); }

Statistics StatisticsFromJson(const std::string& text, const std::string& origin) {
  Statistics s;
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(origin + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw InputError(origin + ": expected an object of statistics");
  for (const auto& [name, values] : j.items()) {
    if (!values.is_array()) throw InputError(origin + ": /" + name + ": expected a list of numbers");
    std::vector<double> v;
    for (const auto& x : values) {
      if (x.is_null()) v.push_back(std::numeric_limits<double>::quiet_NaN());
      else if (x.is_number()) v.push_back(x.get<double>());
      else throw InputError(origin + ": /" + name + ": expected numbers or null");
    }
    s[name] = std::move(v);
  }
  return s;
}

OutputKind ValidationFolderOutput() {
  return {"a validation folder (validation.json, report.html, runs/)", true, [](const fs::path& dir) {
            std::error_code ec;
            const fs::path marker = dir / "validation.json";
            if (!fs::is_regular_file(marker, ec)) return false;
            try {
              return json::parse(ReadInputFile(marker, "validation folder")).value("format", "") == kFolderFormat;
            } catch (...) {
              return false;
            }
          }};
}

int ValidateSummary::Count(Verdict verdict) const {
  int n = 0;
  for (const auto& per_profile : results)
    for (const TestResult& r : per_profile) n += r.verdict == verdict;
  return n;
}

std::string ValidateSummary::BriefReport() const {
  std::string s;
  for (std::size_t p = 0; p < results.size(); ++p) {
    s += "profile " + profiles[p].name + ":\n";
    for (const TestResult& r : results[p]) {
      char line[256];
      std::snprintf(line, sizeof line, "  %-28s %-10s", r.test_id.c_str(), ToString(r.verdict).c_str());
      s += line;
      for (const CriterionVerdict& c : r.criteria) {
        for (const CaseVerdict& v : c.cases)
          if (v.judged && !v.pass) {
            s += " " + c.criterion.statistic + (v.case_name == "base" || v.case_name == "all" ? "" : "@" + v.case_name) +
                 " " + v.text.substr(0, v.text.find(',')) + " vs " + v.expected.substr(0, v.expected.find(" (")) + ";";
          }
      }
      if (!r.error.empty()) s += " " + r.error;
      s += "\n";
    }
  }
  char tail[200];
  std::snprintf(tail, sizeof tail, "%d passed, %d failed, %d documented, %d errors (%.0f s)\n", Count(Verdict::kPass),
                Count(Verdict::kFail), Count(Verdict::kDocuments), Count(Verdict::kError), wall_s);
  s += tail;
  if (interrupted) s += "interrupted: run the same command again to continue\n";
  for (const fs::path& f : {html, pdf, json, csv})
    if (!f.empty()) s += "wrote " + f.string() + "\n";
  for (const std::string& n : notes) s += "note: " + n + "\n";
  return s;
}

int ValidateSummary::ExitStatus() const {
  if (interrupted) return 130;
  return Count(Verdict::kFail) + Count(Verdict::kError) > 0 ? 1 : 0;
}

ValidateSummary RunValidation(const ValidateOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const auto start = std::chrono::steady_clock::now();
  ValidateSummary summary;
  for (const fs::path& p : options.profiles) summary.profiles.push_back(LoadProfile(p));
  if (summary.profiles.size() == 2 && summary.profiles[0].name == summary.profiles[1].name)
    throw InputError("--profile: two profiles named \"" + summary.profiles[0].name + "\"; expected two different ones");
  for (ValidationTest& t : LoadSuite(options.suite)) {
    if (options.quick && !t.quick) continue;
    if (!options.only.empty() && !std::count(options.only.begin(), options.only.end(), t.id)) continue;
    summary.tests.push_back(std::move(t));
  }
  for (const std::string& id : options.only)
    if (std::none_of(summary.tests.begin(), summary.tests.end(), [&](const ValidationTest& t) { return t.id == id; }))
      throw InputError("--test " + id + ": no such test in " + options.suite.string() + (options.quick ? " (with --quick)" : ""));
  if (summary.tests.empty()) throw InputError(options.suite.string() + ": no test to run" + (options.quick ? " with --quick" : ""));
  // Every test's runs are checked before the first starts.
  for (const Profile& p : summary.profiles)
    for (const ValidationTest& t : summary.tests) {
      const sweep::SweepSpec spec = sweep::ParseSweep(SweepOf(t, p, options.seeds).dump(), t.file.string() + " with profile " + p.name, t.file.parent_path());
      sweep::ValidateRuns(spec, sweep::ExpandRuns(spec));
    }
  // The chromium before any work.
  const std::string chromium = options.pdf ? reports::html::ChromiumOrError(options.chromium) : "";
  CreateOutputFolder(options.output_dir);
  json marker = {{"format", kFolderFormat}, {"suite", fs::absolute(options.suite).string()}, {"profiles", json::array()}};
  for (const Profile& p : summary.profiles) marker["profiles"].push_back(json::parse(p.canonical_json));
  WriteFileAtomically(options.output_dir / "validation.json", marker.dump(1));

  std::map<std::string, std::optional<Statistics>> data;
  for (const ValidationTest& t : summary.tests) data[t.id] = MeasureData(t);
  summary.results.assign(summary.profiles.size(), {});
  for (std::size_t p = 0; p < summary.profiles.size(); ++p)
    for (const ValidationTest& t : summary.tests) {
      Say(options, "[" + summary.profiles[p].name + "] " + t.id + ": " + t.title + " ...");
      TestRun tr = RunTest(t, summary.profiles[p], options);
      if (tr.interrupted) {
        summary.interrupted = true;
        summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return summary;
      }
      TestResult r = Judge(t, summary.profiles[p].name, std::move(tr.runs), data[t.id]);
      r.wall_s = tr.wall_s;
      if (tr.setup.is_object()) {
        for (const auto& w : tr.setup["walls"]) {
          std::vector<Vec2> line;
          for (const auto& q : w) line.push_back({q[0].get<double>(), q[1].get<double>()});
          r.walls.push_back(line);
        }
        for (const auto& q : tr.setup["start"]) r.start_positions.push_back({q[0].get<double>(), q[1].get<double>()});
      }
      Say(options, "[" + summary.profiles[p].name + "] " + t.id + ": " + ToString(r.verdict));
      summary.results[p].push_back(std::move(r));
    }
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  WriteValidationReport(options, chromium, &summary);
  return summary;
}

}  // namespace crowdrecon::validate
