// Reading validation tests, profiles and suites (validation_test.hpp).
#include "crowdrecon/validate/validation_test.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/scenario/profile.hpp"

namespace crowdrecon::validate {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr double kHuge = 1e12;

template <typename Enum>
struct Named {
  Enum value;
  const char* name;
};

const std::vector<Named<Role>> kRoles = {
    {Role::kVerification, "verification"}, {Role::kFit, "fit"}, {Role::kHeldOut, "held-out"}};
const std::vector<Named<Aggregate>> kAggregates = {{Aggregate::kEvery, "every"}, {Aggregate::kMedian, "median"},
                                                   {Aggregate::kMean, "mean"},   {Aggregate::kMin, "min"},
                                                   {Aggregate::kMax, "max"},     {Aggregate::kP95, "p95"}};
const std::vector<Named<CriterionKind>> kCriterionKeys = {
    {CriterionKind::kWithin, "within"},           {CriterionKind::kNearReference, "near_reference"},
    {CriterionKind::kWithinData, "within_data"},  {CriterionKind::kNearData, "near_data"},
    {CriterionKind::kDataBand, "data_band"},      {CriterionKind::kIncreasing, "increasing"},
    {CriterionKind::kRatio, "ratio"},             {CriterionKind::kDocuments, "documents"},
    {CriterionKind::kFollows, "follows"}};

template <typename Enum>
std::vector<std::string> NamesOf(const std::vector<Named<Enum>>& table) {
  std::vector<std::string> names;
  for (const auto& n : table) names.emplace_back(n.name);
  return names;
}

template <typename Enum>
std::string NameIn(const std::vector<Named<Enum>>& table, Enum value) {
  for (const auto& n : table)
    if (n.value == value) return n.name;
  return "?";
}

template <typename Enum>
bool ValueIn(const std::vector<Named<Enum>>& table, const std::string& name, Enum* value) {
  for (const auto& n : table)
    if (name == n.name) return *value = n.value, true;
  return false;
}

template <typename Enum>
Enum ValueOf(const std::vector<Named<Enum>>& table, const std::string& name) {
  for (const auto& n : table)
    if (name == n.name) return n.value;
  return table.front().value;  // (names are checked by Choice before)
}

// Whether an override's value is a file path (resolved against the test's
// folder, where it was written, not the sweep's that the runner writes).
bool IsPathKey(const std::string& key) {
  const auto ends = [&](const std::string& tail) {
    return key.size() >= tail.size() && key.compare(key.size() - tail.size(), tail.size(), tail) == 0;
  };
  return key == "venue" || ends(".reference") || ends(".anthropometry") || ends(".rate_csv");
}

std::vector<sweep::Override> ReadOverrides(const JsonReader& r, const fs::path& base_dir) {
  if (!r.IsObject()) r.Fail("expected an object of overrides {\"dotted.path\": value, ...}");
  std::vector<sweep::Override> out;
  for (const std::string& key : r.Keys()) {
    const JsonReader v = r.At(key);
    if (key.empty() || key.front() == '.' || key.back() == '.' || key.find("..") != std::string::npos)
      v.Fail("expected a dotted scenario path such as \"population.count\"");
    json value = v.Raw();
    if (IsPathKey(key) && value.is_string()) {
      const fs::path file = fs::absolute(base_dir / value.get<std::string>()).lexically_normal();
      CheckInputFile(file, "the file of override " + key + " (" + v.Where() + ")");
      value = file.string();
    }
    out.push_back({key, value.dump()});
  }
  return out;
}

observe::Line ReadLine(const JsonReader& r, const std::string& name) {
  const std::vector<Vec2> p = r.AsPoints(2);
  if (p.size() != 2) r.Fail("expected a segment [[x, y], [x, y]]");
  if (Length(p[1] - p[0]) <= 0.0) r.Fail("expected a segment of length > 0");
  observe::Line line;
  line.name = name;
  line.a_m = p[0];
  line.b_m = p[1];
  return line;
}

MeasureSpec ReadMeasure(const JsonReader& r) {
  MeasureSpec m;
  const std::string kind = r.String("kind");
  if (!FromString(kind, &m.kind)) r.At("kind").Fail("unknown measure; expected one of " + MeasureKindNames());
  if (m.kind == MeasureKind::kTravel) {
    m.from_line = ReadLine(r.At("from"), "from");
    m.to_line = ReadLine(r.At("to"), "to");
  }
  if (m.kind == MeasureKind::kPassages) m.line = ReadLine(r.At("line"), "line");
  if (m.kind == MeasureKind::kPassages || m.kind == MeasureKind::kLanes) {
    const JsonReader d = r.At("direction");
    if (m.kind == MeasureKind::kPassages && d.IsString()) {
      // Passages either way: the total flow of a counter-flow.
      if (d.AsString() != "both") d.Fail("expected a direction [dx, dy] of length > 0, or \"both\"");
      m.direction = {0.0, 0.0};
    } else {
      m.direction = d.AsPoint();
      if (!(Length(m.direction) > 0.0)) d.Fail("expected a direction [dx, dy] of length > 0");
      m.direction = Normalized(m.direction);
    }
  }
  if (const auto area = r.Find("area")) {
    m.has_area = true;
    m.area.name = "area";
    m.area.polygon_m = area->AsPoints(3);
    if (!(m.area.Area_m2() > 1e-9)) area->Fail("expected a polygon with an area > 0");
  }
  m.skip_s = r.Number("skip_s", m.skip_s, 0.0, 1e6);
  m.velocity_span_s = r.Number("velocity_span_s", m.velocity_span_s, 0.01, 10.0);
  m.lane_half_width_m = r.Number("lane_half_width_m", m.lane_half_width_m, 0.01, 5.0);
  m.max_headway_m = r.Number("max_headway_m", m.max_headway_m, 0.01, 100.0);
  m.frame_step = int(r.Integer("frame_step", m.frame_step, 1, 1000));
  m.group = r.String("group", "");
  r.Finish();
  std::string error;
  if (!m.IsValid(&error)) r.Fail(error);
  return m;
}

std::pair<double, double> ReadRange(const JsonReader& r) {
  if (!r.IsArray() || r.Size() != 2) r.Fail("expected [low, high] (null for an open end)");
  const auto bound = [&](std::size_t i, double open) {
    const JsonReader e = r.Element(i);
    return e.IsNull() ? open : e.AsNumber(-kHuge, kHuge);
  };
  const double lo = bound(0, -std::numeric_limits<double>::infinity());
  const double hi = bound(1, std::numeric_limits<double>::infinity());
  if (!(lo <= hi)) r.Fail("expected low <= high");
  return {lo, hi};
}

Criterion ReadCriterion(const JsonReader& r, const std::set<std::string>& case_names, bool has_data) {
  Criterion c;
  c.statistic = r.String("statistic");
  c.aggregate = ValueOf(kAggregates, r.Choice("aggregate", "median", NamesOf(kAggregates)));
  int kinds = 0;
  for (const auto& k : kCriterionKeys)
    if (r.Has(k.name)) {
      c.kind = k.value;
      ++kinds;
    }
  if (kinds != 1)
    r.Fail("expected exactly one of within, near_reference, within_data, near_data, data_band, increasing, ratio, "
           "documents, follows");
  switch (c.kind) {
    case CriterionKind::kWithin: std::tie(c.low, c.high) = ReadRange(r.At("within")); break;
    case CriterionKind::kNearReference: c.relative = r.Number("near_reference", 0.0, 10.0); break;
    case CriterionKind::kNearData: c.relative = r.Number("near_data", 0.0, 10.0); break;
    case CriterionKind::kWithinData: {
      std::tie(c.quantile_low, c.quantile_high) = ReadRange(r.At("within_data"));
      if (c.quantile_low < 0 || c.quantile_high > 1) r.At("within_data").Fail("expected quantiles in [0, 1]");
      break;
    }
    case CriterionKind::kDataBand: {
      const JsonReader b = r.At("data_band");
      c.band_sd = b.Number("sd", c.band_sd, 0.1, 10.0);
      c.band_width_per_m2 = b.Number("density_width_per_m2", c.band_width_per_m2, 0.05, 5.0);
      b.Finish();
      break;
    }
    case CriterionKind::kIncreasing: {
      if (!r.Bool("increasing", true)) r.At("increasing").Fail("expected true");
      break;
    }
    case CriterionKind::kRatio: {
      const JsonReader q = r.At("ratio");
      c.case_a = q.String("of");
      c.case_b = q.String("to");
      std::tie(c.low, c.high) = ReadRange(q.At("within"));
      for (const std::string& n : {c.case_a, c.case_b})
        if (!case_names.count(n)) q.Fail("\"" + n + "\" is not a case of this test");
      q.Finish();
      break;
    }
    case CriterionKind::kDocuments: {
      if (!r.Bool("documents", true)) r.At("documents").Fail("expected true");
      break;
    }
    case CriterionKind::kFollows: {
      const JsonReader f = r.At("follows");
      if (!f.IsObject()) f.Fail("expected a distribution: {\"gamma\": {\"shape\": a, \"scale_s\": b}} and the like");
      c.distribution = ReadDistribution(f);
      f.Finish();
      c.alpha = r.Number("alpha", c.alpha, 0.001, 0.5);
      break;
    }
  }
  if (c.kind != CriterionKind::kFollows && r.Has("alpha")) r.At("alpha").Fail("applies to \"follows\" only");
  const bool needs_data = c.kind == CriterionKind::kWithinData || c.kind == CriterionKind::kNearData ||
                          c.kind == CriterionKind::kDataBand;
  if (needs_data && !has_data) r.Fail("this criterion compares with the data; the test has no \"data\"");
  if (const auto cases = r.Find("cases"))
    for (std::size_t i = 0; i < cases->Size(); ++i) {
      c.cases.push_back(cases->Element(i).AsString());
      if (!case_names.count(c.cases.back())) cases->Element(i).Fail("not a case of this test");
    }
  c.why = r.String("why");
  if (c.why.empty()) r.At("why").Fail("expected the tolerance's reason");
  r.Finish();
  return c;
}

std::vector<std::uint64_t> ReadSeeds(const JsonReader& r) {
  std::vector<std::uint64_t> seeds;
  if (r.IsArray()) {
    for (std::size_t i = 0; i < r.Size(); ++i) seeds.push_back(std::uint64_t(r.Element(i).AsNumber(0, 1e15)));
  } else {
    const long long first = r.Integer("first", 1, 0, 1'000'000'000'000LL);
    const long long count = r.Integer("count", 1, 1000);
    for (long long k = 0; k < count; ++k) seeds.push_back(std::uint64_t(first + k));
    r.Finish();
  }
  if (seeds.empty()) r.Fail("expected at least one seed");
  return seeds;
}

}  // namespace

std::string ToString(Role role) { return NameIn(kRoles, role); }
bool FromString(const std::string& name, Role* role) { return ValueIn(kRoles, name, role); }
std::string ToString(Aggregate aggregate) { return NameIn(kAggregates, aggregate); }
bool FromString(const std::string& name, Aggregate* aggregate) { return ValueIn(kAggregates, name, aggregate); }
std::string ToString(CriterionKind kind) { return NameIn(kCriterionKeys, kind); }

std::string Criterion::Describe() const {
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return std::string(b);
  };
  const std::string what = statistic + " (" + ToString(aggregate) + ")";
  switch (kind) {
    case CriterionKind::kWithin:
      if (std::isinf(low)) return what + " <= " + num(high);
      if (std::isinf(high)) return what + " >= " + num(low);
      return what + " in [" + num(low) + ", " + num(high) + "]";
    case CriterionKind::kNearReference: return what + " within " + num(100 * relative) + " % of the published values";
    case CriterionKind::kWithinData:
      return what + " within the data's " + num(100 * quantile_low) + "-" + num(100 * quantile_high) + " % quantiles";
    case CriterionKind::kNearData: return what + " within " + num(100 * relative) + " % of the data's";
    case CriterionKind::kDataBand:
      return "mean speed within " + num(band_sd) + " SD of the data's at the same density (+-" +
             num(band_width_per_m2 / 2) + " /m2)";
    case CriterionKind::kIncreasing: return what + " rises from case to case";
    case CriterionKind::kRatio:
      return what + ": " + case_b + " / " + case_a +
             (std::isinf(high) ? " >= " + num(low)
                               : std::isinf(low) ? " <= " + num(high) : " in [" + num(low) + ", " + num(high) + "]");
    case CriterionKind::kDocuments: return what + " (documented, no pass band)";
    case CriterionKind::kFollows:
      return statistic + " follows " + distribution.Describe() + " (Kolmogorov-Smirnov, alpha " + num(alpha) + ")";
  }
  return what;
}

ValidationTest ParseValidationTest(const std::string& text, const std::string& origin, const fs::path& base_dir) {
  const JsonDocument doc = JsonDocument::Parse(text, origin);
  const JsonReader r = doc.Root();
  if (!r.IsObject()) r.Fail("expected a validation test object");
  if (r.String("format") != "crowdrecon-validation-test")
    r.At("format").Fail("expected \"crowdrecon-validation-test\"");
  r.Integer("version", 1, 1);
  ValidationTest t;
  t.id = r.At("id").AsName();
  t.title = r.String("title");
  t.standard = r.String("standard");
  t.source = r.String("source");
  t.setup = r.String("setup");
  FromString(r.Choice("role", NamesOf(kRoles)), &t.role);
  if (const auto notes = r.Find("notes"))
    for (std::size_t i = 0; i < notes->Size(); ++i) t.notes.push_back(notes->Element(i).AsString());
  const JsonReader sc = r.At("scenario");
  t.scenario = fs::absolute(base_dir / sc.AsString()).lexically_normal();
  CheckInputFile(t.scenario, "the test's scenario (" + sc.Where() + ")");
  if (const auto set = r.Find("set")) t.set = ReadOverrides(*set, base_dir);
  t.seeds = r.Has("seeds") ? ReadSeeds(r.At("seeds")) : std::vector<std::uint64_t>{1};
  t.x_label = r.String("x_label", "");
  std::set<std::string> case_names;
  if (const auto cases = r.Find("cases")) {
    if (!cases->IsArray() || cases->Size() == 0) cases->Fail("expected a list of cases");
    for (std::size_t i = 0; i < cases->Size(); ++i) {
      const JsonReader c = cases->Element(i);
      Case k;
      k.name = c.At("name").AsName();
      if (!case_names.insert(k.name).second) c.At("name").Fail("a second case of this name");
      k.label = c.String("label", k.name);
      k.x = c.Number("x", std::numeric_limits<double>::quiet_NaN(), -kHuge, kHuge);
      if (const auto set = c.Find("set")) k.set = ReadOverrides(*set, base_dir);
      if (const auto ref = c.Find("reference")) {
        for (std::size_t j = 0; j < ref->Size(); ++j) k.reference.push_back(ref->Element(j).AsNumber(-kHuge, kHuge));
        if (k.reference.empty()) ref->Fail("expected at least one published value");
      }
      c.Finish();
      t.cases.push_back(std::move(k));
    }
  } else {
    t.cases.push_back(Case{"base", "", std::numeric_limits<double>::quiet_NaN(), {}, {}});
    case_names.insert("base");
  }
  t.measure = ReadMeasure(r.At("measure"));
  t.measure_json = doc.Json().at("measure").dump();
  if (const auto data = r.Find("data")) {
    DataReference d;
    const JsonReader file = data->At("trajectories");
    d.trajectories = fs::absolute(base_dir / file.AsString()).lexically_normal();
    d.label = data->String("label", d.trajectories.filename().string());
    d.unit = data->Choice("unit", "", {"", "m", "cm", "mm"});
    // The data's own geometry (lines, area) where it differs from the run's.
    d.measure = t.measure;
    if (const auto m = data->Find("measure")) d.measure = ReadMeasure(*m);
    if (d.measure.kind != t.measure.kind) data->At("measure").Fail("the data's measure must be of the test's kind");
    data->Finish();
    t.data = std::move(d);
  }
  if (const auto criteria = r.Find("criteria"))
    for (std::size_t i = 0; i < criteria->Size(); ++i)
      t.criteria.push_back(ReadCriterion(criteria->Element(i), case_names, t.data.has_value()));
  // Every statistic a criterion or the figure names is one the measure gives
  // (issue 65, K19: a misspelt one was found after the runs, as a failure).
  if (const auto criteria = r.Find("criteria"))
    for (std::size_t i = 0; i < t.criteria.size(); ++i)
      if (const std::string why = UnknownStatistic(t.measure.kind, t.criteria[i].statistic); !why.empty())
        criteria->Element(i).At("statistic").Fail(why);
  // A test with nothing to judge or show would run its seeds for nothing
  // (issue 65, the adversarial pass's K17).
  if (t.criteria.empty())
    (r.Has("criteria") ? r.At("criteria") : r)
        .Fail("expected at least one criterion (a test judges or documents a statistic: \"criteria\": [{...}])");
  for (const Criterion& c : t.criteria)
    if (c.kind == CriterionKind::kNearReference)
      for (const Case& k : t.cases)
        if (c.AppliesTo(k.name) && k.reference.empty())
          r.At("criteria").Fail("near_reference needs published values (\"reference\") in case \"" + k.name + "\"");
  if (const auto fig = r.Find("figure")) {
    const std::string kind = fig->Choice("kind", "distribution", {"distribution", "cumulative"});
    t.figure.kind = kind == "cumulative" ? FigureSpec::Kind::kCumulative : FigureSpec::Kind::kDistribution;
    t.figure.statistic = fig->String("statistic", "");
    if (const std::string why = UnknownStatistic(t.measure.kind, t.figure.statistic); !t.figure.statistic.empty() && !why.empty())
      fig->At("statistic").Fail(why);
    t.figure.log = fig->Bool("log", false);
    if (t.figure.kind == FigureSpec::Kind::kCumulative && t.measure.kind != MeasureKind::kPassages)
      fig->At("kind").Fail("a cumulative figure counts passages; the test's measure is " + ToString(t.measure.kind));
    fig->Finish();
  }
  t.quick = r.Bool("quick", false);
  r.Finish();
  return t;
}

ValidationTest LoadValidationTest(const fs::path& file) {
  ValidationTest t = ParseValidationTest(ReadInputFile(file, "validation test"), file.string(), file.parent_path());
  t.file = fs::absolute(file).lexically_normal();
  if (t.id != file.stem().string())
    throw InputError(file.string() + ": /id: \"" + t.id + "\", expected the file's name without .json (\"" +
                     file.stem().string() + "\"), so that a test is found by its id");
  return t;
}

Profile ParseProfile(const std::string& text, const std::string& origin, const fs::path& base_dir) {
  // The format is the scenarios' (scenario/profile.hpp): one reader.
  const scenario::ModelProfile m = scenario::ParseModelProfile(text, origin, base_dir);
  Profile p;
  p.name = m.name;
  p.description = m.description;
  for (const auto& [key, value] : m.model) p.set.push_back({"model." + key, value});
  if (!m.body_json.empty()) p.set.push_back({"population.body", m.body_json});
  // The crowd's free speeds where a test does not prescribe them (a test
  // case that sets them comes after the profile).
  if (m.desired_speed_m_per_s)
    p.set.push_back({"population.desired_speed_m_per_s",
                     json::array({m.desired_speed_m_per_s->first, m.desired_speed_m_per_s->second}).dump()});
  p.canonical_json = m.canonical_json;
  return p;
}

Profile LoadProfile(const fs::path& file) {
  Profile p = ParseProfile(ReadInputFile(file, "profile"), file.string(), file.parent_path());
  p.file = fs::absolute(file).lexically_normal();
  return p;
}

std::vector<ValidationTest> LoadSuite(const fs::path& suite) {
  std::error_code ec;
  if (!fs::is_directory(suite, ec)) return {LoadValidationTest(suite)};
  const fs::path dir = suite / "tests";
  if (!fs::is_directory(dir, ec))
    throw InputError(suite.string() + ": a folder without tests/; expected a suite folder (venues/validation) or a "
                     "test file");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir.string() + ": no tests (*.json)");
  std::vector<ValidationTest> tests;
  for (const fs::path& f : files) tests.push_back(LoadValidationTest(f));
  return tests;
}

}  // namespace crowdrecon::validate
