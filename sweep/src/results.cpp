#include "crowdrecon/sweep/results.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "crowdrecon/scenario/profile.hpp"

#include "crowdrecon/sweep/version.hpp"  // generated at build time: CROWDRECON_GIT_VERSION

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "crowdrecon-sweep-results";

std::string Quoted(const std::string& identifier) {
  std::string out = "\"";
  for (char c : identifier) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// Column names and SQL types of the runs table, in order.
std::vector<std::pair<std::string, std::string>> RunColumns(const SweepSpec& spec) {
  std::vector<std::pair<std::string, std::string>> c = {
      {"run_index", "INTEGER PRIMARY KEY"}, {"run_id", "TEXT"}, {"variant", "TEXT"}, {"seed", "INTEGER"}};
  for (const Axis& a : spec.axes) c.emplace_back(a.path, a.numeric() ? "REAL" : "TEXT");
  c.emplace_back("status", "TEXT");
  c.emplace_back("regime", "TEXT");
  c.emplace_back("regime_reason", "TEXT");
  for (const std::string& m : MetricColumns()) c.emplace_back(m, "REAL");
  c.emplace_back("wall_s", "REAL");
  return c;
}

std::map<std::string, std::string> SweepValues(const SweepSpec& spec, const std::string& analysis_options_json) {
  json axes = json::array(), variants = json::array(), seeds = json::array();
  for (const Axis& a : spec.axes) axes.push_back(a.path);
  for (const Variant& v : spec.variants) variants.push_back(v.name);
  for (std::uint64_t s : spec.seeds) seeds.push_back(s);
  return {{"format", kFormat},
          {"version", "1"},
          {"name", spec.name},
          {"sweep", spec.canonical_json},
          {"sweep_file", spec.file.string()},
          {"scenario", spec.scenario_canonical_json},
          {"scenario_file", spec.scenario_file.string()},
          {"analysis_options", analysis_options_json},
          {"axes", axes.dump()},
          {"variants", variants.dump()},
          {"seeds", seeds.dump()},
          {"diagram_x", spec.diagram_x},
          {"diagram_y", spec.diagram_y},
          {"runs_total", std::to_string(spec.RunCount())},
          {"crowdrecon_version", CROWDRECON_GIT_VERSION},
          {"source_fingerprint", CROWDRECON_SOURCE_FINGERPRINT}};
}

// Appends raw bytes of trivially copyable values and strings.
struct Writer {
  std::string out;
  template <typename T>
  void Put(T v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void PutString(const std::string& s) {
    Put<std::uint64_t>(s.size());
    out += s;
  }
};

struct Reader {
  const std::string& in;
  std::size_t at = 0;
  template <typename T>
  T Get() {
    if (at + sizeof(T) > in.size()) throw std::runtime_error("sweep: truncated result message");
    T v;
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string GetString() {
    const auto n = Get<std::uint64_t>();
    if (at + n > in.size()) throw std::runtime_error("sweep: truncated result message");
    std::string s = in.substr(at, n);
    at += n;
    return s;
  }
};

}  // namespace

const std::vector<std::string>& RiskColumns() {
  static const std::vector<std::string> columns = {"people_uncomfortable", "people_danger", "people_beyond_tolerance",
                                                   "max_chest_load_n", "longest_above_f0_s"};
  return columns;
}

const std::vector<std::string>& MetricColumns() {
  static const std::vector<std::string> columns = [] {
    analysis::RunAnalysis template_run;
    template_run.group_mean_speed_m_per_s = {0.0, 0.0};  // main flow and counter-flow
    std::vector<std::string> names;
    for (const analysis::SummaryValue& v : template_run.SummaryTable()) names.push_back(v.name);
    for (const std::string& name : RiskColumns()) names.push_back(name);
    return names;
  }();
  return columns;
}

std::string SerializeRow(const ResultRow& row) {
  Writer w;
  w.Put<std::uint64_t>(row.run_index);
  w.PutString(row.status);
  w.PutString(row.regime);
  w.PutString(row.regime_reason);
  w.Put<std::uint64_t>(row.metrics.size());
  for (double m : row.metrics) w.Put(m);
  w.Put(row.wall_s);
  return w.out;
}

ResultRow DeserializeRow(const std::string& bytes) {
  Reader r{bytes};
  ResultRow row;
  row.run_index = r.Get<std::uint64_t>();
  row.status = r.GetString();
  row.regime = r.GetString();
  row.regime_reason = r.GetString();
  const auto n = r.Get<std::uint64_t>();
  if (n > bytes.size()) throw std::runtime_error("sweep: corrupt result message");
  for (std::uint64_t i = 0; i < n; ++i) row.metrics.push_back(r.Get<double>());
  row.wall_s = r.Get<double>();
  return row;
}

struct ResultsStore::Impl {
  fs::path dir;
  std::unique_ptr<sqlite::Database> db;
  const SweepSpec* spec = nullptr;
  const std::vector<RunPlan>* runs = nullptr;
  std::vector<std::pair<std::string, std::string>> columns;
};

ResultsStore::ResultsStore(const fs::path& dir, const SweepSpec& spec, const std::vector<RunPlan>& runs,
                           const std::string& analysis_options_json)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.dir = dir;
  m.spec = &spec;
  m.runs = &runs;
  m.columns = RunColumns(spec);
  const fs::path file = sqlite_file();
  m.db = std::make_unique<sqlite::Database>(file.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  // An empty file (new, or a sweep killed while creating it) is started afresh.
  bool exists = false;
  {
    sqlite::Statement tables(*m.db, "SELECT COUNT(*) FROM sqlite_master");
    exists = tables.Next() && tables.Int(0) > 0;
  }
  const std::map<std::string, std::string> values = SweepValues(spec, analysis_options_json);
  if (!exists) {
    std::string create = "CREATE TABLE runs (";
    for (std::size_t i = 0; i < m.columns.size(); ++i)
      create += (i ? ", " : "") + Quoted(m.columns[i].first) + " " + m.columns[i].second;
    create += ")";
    m.db->Exec("BEGIN");
    m.db->Exec(create);
    m.db->Exec("CREATE TABLE sweep (key TEXT PRIMARY KEY, value TEXT)");
    sqlite::Statement insert(*m.db, "INSERT INTO sweep (key, value) VALUES (?, ?)");
    for (const auto& [key, value] : values) {
      insert.Bind(1, key).Bind(2, value);
      insert.Run();
    }
    m.db->Exec("COMMIT");
  } else {
    // Continue only the same sweep: same sweep JSON, same base scenario, same
    // analysis, same columns.
    std::map<std::string, std::string> stored;
    try {
      sqlite::Statement select(*m.db, "SELECT key, value FROM sweep");
      while (select.Next()) stored[select.Text(0)] = select.Text(1);
    } catch (const InputError&) {
      throw InputError(file.string() + ": not the results of a crowdrecon sweep; give a new output folder");
    }
    if (stored["format"] != kFormat)
      throw InputError(file.string() + ": not the results of a crowdrecon sweep; give a new output folder");
    const auto differs = [&](const char* key, const std::string& what) {
      if (stored[key] != values.at(key))
        throw InputError(file.string() + " holds the results of a different sweep (" + what +
                         " changed since it was started); use a new output folder (-o), or delete " +
                         dir.string() + " to start over");
    };
    // Runs of other sources may differ (the engine may have changed): a sweep
    // is finished by a crowdrecon built from the sources that started it
    // (the same source fingerprint: another commit of documents or results
    // continues it). A sweep stored before fingerprints: the same version.
    const bool same_build = stored.count("source_fingerprint")
                                ? stored["source_fingerprint"] == values.at("source_fingerprint")
                                : stored["crowdrecon_version"] == values.at("crowdrecon_version");
    if (!same_build)
      throw InputError(file.string() + " holds runs made by crowdrecon " + stored["crowdrecon_version"] +
                       (stored.count("source_fingerprint") ? " (sources " + stored["source_fingerprint"] + ")" : std::string()) +
                       "; this is crowdrecon " + values.at("crowdrecon_version") + " (sources " +
                       values.at("source_fingerprint") + ")" +
                       ", whose results may differ and are not mixed with them; use a new output folder (-o), or "
                       "delete " + dir.string() + " to start over");
    differs("sweep", "the sweep file");
    differs("scenario", "the scenario " + spec.scenario_file.string());
    differs("analysis_options", "the analysis options");
    std::vector<std::string> names;
    sqlite::Statement info(*m.db, "PRAGMA table_info(runs)");
    while (info.Next()) names.push_back(info.Text(1));
    std::vector<std::string> expected;
    for (const auto& c : m.columns) expected.push_back(c.first);
    if (names != expected)
      throw InputError(file.string() + " was written by a crowdrecon with other result columns; use a new output "
                       "folder (-o)");
    sqlite::Statement select(*m.db, "SELECT run_index FROM runs");
    while (select.Next()) done_.insert(static_cast<std::size_t>(select.Int(0)));
  }
}

ResultsStore::~ResultsStore() = default;

fs::path ResultsStore::sqlite_file() const { return impl_->dir / "results.sqlite"; }
fs::path ResultsStore::csv_file() const { return impl_->dir / "results.csv"; }

void ResultsStore::Commit(const ResultRow& row) {
  Impl& m = *impl_;
  const RunPlan& run = m.runs->at(row.run_index);
  const SweepSpec& spec = *m.spec;
  std::string sql = "INSERT INTO runs VALUES (";
  for (std::size_t i = 0; i < m.columns.size(); ++i) sql += i ? ", ?" : "?";
  sql += ")";
  sqlite::Statement insert(*m.db, sql);
  int k = 1;
  insert.Bind(k++, static_cast<std::int64_t>(run.index));
  insert.Bind(k++, run.id);
  insert.Bind(k++, spec.variants[run.variant].name);
  insert.Bind(k++, static_cast<std::int64_t>(run.seed));
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (spec.axes[a].numeric()) insert.Bind(k++, spec.axes[a].numbers[run.axis_value[a]]);
    else insert.Bind(k++, AxisValueText(spec.axes[a], run.axis_value[a]));
  }
  insert.Bind(k++, row.status);
  if (row.regime.empty()) insert.BindNull(k++);
  else insert.Bind(k++, row.regime);
  if (row.regime_reason.empty()) insert.BindNull(k++);
  else insert.Bind(k++, row.regime_reason);
  const std::size_t metric_count = MetricColumns().size();
  for (std::size_t i = 0; i < metric_count; ++i)
    insert.Bind(k++, i < row.metrics.size() ? row.metrics[i] : std::numeric_limits<double>::quiet_NaN());
  insert.Bind(k++, row.wall_s);
  insert.Run();
  done_.insert(row.run_index);
}

void ResultsStore::WriteCsv() const {
  const Impl& m = *impl_;
  const fs::path file = csv_file();
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(tmp.string() + ": cannot write the results table");
    for (std::size_t i = 0; i < m.columns.size(); ++i) out << (i ? "," : "") << CsvField(m.columns[i].first);
    out << "\n";
    sqlite::Statement select(*m.db, "SELECT * FROM runs ORDER BY run_index");
    const int n = static_cast<int>(m.columns.size());
    while (select.Next()) {
      for (int c = 0; c < n; ++c) {
        if (c) out << ",";
        switch (select.Type(c)) {
          case SQLITE_NULL: break;
          case SQLITE_INTEGER: out << select.Int(c); break;
          case SQLITE_FLOAT: out << ExactNumber(select.Double(c)); break;
          default: out << CsvField(select.Text(c)); break;
        }
      }
      out << "\n";
    }
    out.flush();
    if (!out) throw InputError(tmp.string() + ": cannot write the results table (disk full?)");
  }
  fs::rename(tmp, file);
}

std::optional<std::size_t> ResultsTable::FindColumn(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  return std::nullopt;
}

std::size_t ResultsTable::Column(const std::string& name) const {
  if (const auto i = FindColumn(name)) return *i;
  throw InputError(file.string() + ": the runs table has no column \"" + name + "\"");
}

std::string SweepProfile(const ResultsTable& table) {
  const auto sweep_text = table.sweep.find("sweep"), scenario_text = table.sweep.find("scenario");
  if (sweep_text == table.sweep.end() || scenario_text == table.sweep.end()) return "";
  const nlohmann::json sweep = nlohmann::json::parse(sweep_text->second, nullptr, false);
  const nlohmann::json scenario = nlohmann::json::parse(scenario_text->second, nullptr, false);
  auto named = [](const nlohmann::json& object, const char* key) -> std::string {
    return object.is_object() && object.contains(key) && object[key].is_string() ? object[key].get<std::string>() : "";
  };
  std::string first = sweep.is_object() && sweep.contains("set") ? named(sweep["set"], "profile") : "";
  if (first.empty()) first = named(scenario, "profile");
  if (first.empty()) first = scenario::kDefaultProfile;
  std::vector<std::string> profiles{first};
  if (sweep.is_object() && sweep.contains("variants") && sweep["variants"].is_array())
    for (const nlohmann::json& v : sweep["variants"]) {
      const std::string own = v.is_object() && v.contains("set") ? named(v["set"], "profile") : "";
      if (!own.empty() && std::find(profiles.begin(), profiles.end(), own) == profiles.end()) profiles.push_back(own);
    }
  // A profile given as a file is named by its own name (as a run file
  // names it): read relative to the scenario's folder, as the scenario does.
  const auto file = table.sweep.find("scenario_file");
  const fs::path folder = file == table.sweep.end() ? fs::path() : fs::path(file->second).parent_path();
  std::string out;
  for (std::string p : profiles) {
    if (!scenario::IsProfileName(p)) try {
        p = scenario::LoadModelProfile(scenario::ProfilePath(p, folder)).name;
      } catch (const InputError&) {  // (moved or gone since: its path is what there is)
      }
    out += (out.empty() ? "" : ", ") + p;
  }
  return out;
}

ResultsTable ReadResults(const fs::path& dir_or_file) {
  ResultsTable t;
  t.file = dir_or_file.extension() == ".sqlite" ? dir_or_file : dir_or_file / "results.sqlite";
  if (!fs::exists(t.file))
    throw InputError(t.file.string() + ": no sweep results here (run `crowdrecon sweep SWEEP.json -o DIR` first)");
  sqlite::Database db(t.file.string(), SQLITE_OPEN_READONLY);
  try {
    sqlite::Statement select(db, "SELECT key, value FROM sweep");
    while (select.Next()) t.sweep[select.Text(0)] = select.Text(1);
  } catch (const InputError&) {
    throw InputError(t.file.string() + ": not the results of a crowdrecon sweep");
  }
  if (t.sweep["format"] != kFormat) throw InputError(t.file.string() + ": not the results of a crowdrecon sweep");
  sqlite::Statement select(db, "SELECT * FROM runs ORDER BY run_index");
  const int n = select.ColumnCount();
  for (int c = 0; c < n; ++c) t.columns.push_back(select.ColumnName(c));
  while (select.Next()) {
    std::vector<ResultsTable::Cell> row(static_cast<std::size_t>(n));
    for (int c = 0; c < n; ++c) {
      ResultsTable::Cell& cell = row[static_cast<std::size_t>(c)];
      const int type = select.Type(c);
      cell.null = type == SQLITE_NULL;
      cell.numeric = type == SQLITE_INTEGER || type == SQLITE_FLOAT;
      if (cell.numeric) cell.number = select.Double(c);
      if (cell.numeric) cell.text = type == SQLITE_INTEGER ? std::to_string(select.Int(c)) : ExactNumber(cell.number);
      else if (!cell.null) cell.text = select.Text(c);
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string BuildVersion() { return CROWDRECON_GIT_VERSION; }

std::string SourceFingerprint() { return CROWDRECON_SOURCE_FINGERPRINT; }

OutputKind SweepFolderOutput() {
  return {"a sweep folder (results.sqlite of a crowdrecon sweep)", true, [](const fs::path& dir) {
    const fs::path file = dir / "results.sqlite";
    std::error_code ec;
    if (fs::is_regular_file(file, ec) && fs::file_size(file, ec) == 0) return true;
    if (!FileStartsWith(file, std::string("SQLite format 3\0", 16))) return false;
    try {
      sqlite::Database db(file.string(), SQLITE_OPEN_READONLY);
      sqlite::Statement format(db, "SELECT value FROM sweep WHERE key = 'format'");
      return format.Next() && format.Text(0) == kFormat;
    } catch (const std::exception&) {  // unreadable or foreign: not ours
      return false;
    }
  }};
}

}  // namespace crowdrecon::sweep
