// Body commands: `shape` (outline -> body), `population`, `body reference`.
// See docs/bodies.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/anthropometry.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/geometry/outline.hpp"
#include "crowdrecon/geometry/population.hpp"
#include "crowdrecon/geometry/population_table.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::cli {

namespace {

using geometry::Body;
using geometry::Spheropolygon;
using viz::Canvas;
using viz::Color;

// The swept shape painted as the union of its pieces (core polygon, a disk per
// vertex, a strip per edge) in one opaque colour, so no boundary assembly is needed.
void FillSwept(Canvas& canvas, const Spheropolygon& shape, Vec2 at, Color fill) {
  const auto& v = shape.vertices();
  const double r = shape.radius();
  std::vector<Vec2> core;
  for (const Vec2& p : v) core.push_back(p + at);
  if (core.size() >= 3) canvas.FillPolygon(core, fill);
  for (std::size_t i = 0; i < core.size(); ++i) {
    canvas.Circle(core[i], r, fill, fill, 0.5);
    if (core.size() < 2) continue;
    const Vec2 a = core[i], b = core[(i + 1) % core.size()];
    if (a == b) continue;
    const Vec2 n = Perp(Normalized(b - a)) * r;
    canvas.FillPolygon({a + n, b + n, b - n, a - n}, fill);
  }
}

void DrawBodyPicture(const Body& body, const std::string& title, const std::string& file) {
  const Spheropolygon& s = body.shape;
  Vec2 lo = s.BoundsMin(), hi = s.BoundsMax();
  for (const Vec2& p : body.outline_m) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  const double ppm = 1400.0;
  const double text_lines = 8.0, line_px = 17.0;
  lo = lo - Vec2{0.03, 0.04};
  hi = hi + Vec2{0.12, 0.03 + text_lines * line_px / ppm};  // room for the front arrow and the text
  Canvas canvas(file, lo, hi, ppm, 30.0);
  canvas.FillPolygon({lo - Vec2{1, 1}, {hi.x + 1, lo.y - 1}, hi + Vec2{1, 1}, {lo.x - 1, hi.y + 1}},
                     Color::White());
  FillSwept(canvas, s, {}, Color::Hex(0xc6dbef));
  for (const Vec2& p : s.SampleBoundary(0.001)) canvas.Dot(p, 1.1, Color::Hex(0x08519c));
  if (!body.outline_m.empty()) {
    std::vector<Vec2> closed = body.outline_m;
    closed.push_back(closed.front());
    canvas.StrokePolyline(closed, Color::Hex(0xd62728), 1.6, /*dashed=*/true);
  }
  canvas.StrokePolygon(s.vertices(), Color::Hex(0x252525), 1.2);
  for (std::size_t i = 0; i < s.size(); ++i) {
    canvas.Dot(s.vertices()[i], 3.0, Color::Hex(0x252525));
    canvas.Text(s.vertices()[i] + Vec2{0.004, 0.004}, std::to_string(i), 10, Color::Hex(0x636363));
  }
  canvas.Dot(s.centroid(), 4.0, Color::Hex(0x2ca02c));
  canvas.Text(s.centroid() + Vec2{0.006, -0.014}, "centroid", 12, Color::Hex(0x2ca02c));
  const double front_x = s.BoundsMax().x;
  canvas.Arrow({0.0, 0.0}, {front_x + 0.08, 0.0}, Color::Hex(0x2ca02c), 2.0);
  canvas.Text({front_x + 0.01, 0.008}, "front (+x)", 12, Color::Hex(0x2ca02c));
  canvas.ScaleBar(0.1);

  const double rho = geometry::kPaperDensityKgPerM2;
  std::vector<std::string> lines = {
      title,
      std::to_string(s.size()) + " vertices, sphero-radius " + FormatNumber(s.radius()) + " m, scale " +
          body.scale_rule,
      "area " + FormatNumber(s.area()) + " m^2, J " + FormatNumber(s.polar_moment()) +
          " m^4, I(rho=1000) " + FormatNumber(rho * s.polar_moment()) + " kg m^2",
      "width " + FormatNumber(s.BoundsMax().y - s.BoundsMin().y) + " m, depth " +
          FormatNumber(s.BoundsMax().x - s.BoundsMin().x) + " m",
      body.hausdorff_m >= 0 ? "Hausdorff(outline, swept) " + FormatNumber(body.hausdorff_m) + " m"
                            : std::string("Hausdorff not computed"),
      "red dashed: outline; blue: swept shape; black: core polygon"};
  for (const std::string& note : body.notes) lines.push_back("note: " + note);
  double y = 24.0;
  for (const std::string& line : lines) {
    canvas.TextPx(30.0, y, line, line == title ? 15.0 : 12.5);
    y += line_px;
  }
  canvas.Finish();
}

void DrawPopulationPicture(const geometry::Population& population, const std::string& file) {
  const std::size_t shown = std::min<std::size_t>(population.people.size(), 100);
  const auto columns = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(shown))));
  const std::size_t rows = (shown + columns - 1) / columns;
  const double cell_m = 0.65, ppm = 160.0, header_m = 0.35;
  const Vec2 lo{0.0, 0.0};
  const Vec2 hi{cell_m * static_cast<double>(columns), cell_m * static_cast<double>(rows) + header_m};
  Canvas canvas(file, lo, hi, ppm, 20.0);
  canvas.FillPolygon({lo - Vec2{1, 1}, {hi.x + 1, lo.y - 1}, hi + Vec2{1, 1}, {lo.x - 1, hi.y + 1}},
                     Color::White());
  for (std::size_t i = 0; i < shown; ++i) {
    const geometry::Person& p = population.people[i];
    const Vec2 centre{(static_cast<double>(i % columns) + 0.5) * cell_m,
                      (static_cast<double>(rows - 1 - i / columns) + 0.55) * cell_m};
    const bool female = p.sex && *p.sex == geometry::Sex::kFemale;
    FillSwept(canvas, p.shape, centre, Color::Hex(female ? 0xfdd0a2 : 0xc6dbef));
    std::vector<Vec2> core;
    for (const Vec2& v : p.shape.vertices()) core.push_back(v + centre);
    if (core.size() >= 3) canvas.StrokePolygon(core, Color::Hex(0x252525), 0.8);
    canvas.Line(centre, centre + Vec2{0.12, 0.0}, Color::Hex(0x2ca02c), 1.5);
    canvas.Dot(centre, 2.0, Color::Hex(0x2ca02c));
    char label[64];
    std::snprintf(label, sizeof label, "%.1f kg", p.mass_kg);
    canvas.Text(centre + Vec2{-0.1, -0.3}, label, 9.5, Color::Hex(0x404040));
  }
  std::string title = "population: " + geometry::ToString(population.options.mode) + ", " +
                      std::to_string(population.people.size()) + " people, seed " +
                      std::to_string(population.options.seed);
  if (shown < population.people.size()) title += " (first " + std::to_string(shown) + " shown)";
  canvas.TextPx(20.0, 30.0, title, 15.0);
  canvas.TextPx(20.0, 50.0,
                "chest faces +x (green tick); cell " + FormatNumber(cell_m) + " m" +
                    (population.options.mode == geometry::PopulationMode::kAnthropometric
                         ? "; blue: male, orange: female"
                         : ""),
                12.0);
  canvas.ScaleBar(0.5);
  canvas.Finish();
}

// --- shape -------------------------------------------------------------------

struct ShapeArgs {
  std::string outline, output, picture, scale, front, region = "dark";
  std::size_t vertices = 18;
  double radius_m = 0.05;
  bool force = false;
};

void RunShape(const ShapeArgs& a, bool scale_given, bool front_given) {
  CheckOutputs({{"-o", a.output, geometry::BodyJsonOutput()}, {"--picture", a.picture, PictureOutputKind()}},
               {{"the outline", a.outline}}, a.force);
  geometry::ImageOutlineOptions image;
  image.region = geometry::ImageRegionFromString(a.region, "--region");
  const geometry::Outline outline = geometry::ReadOutline(a.outline, image);
  geometry::BodyOptions options;
  options.vertex_count = a.vertices;
  options.radius_m = a.radius_m;
  // Images default to the paper's rule (chest depth 0.20 m); point lists are
  // taken as metres unless told otherwise.
  options.scale = scale_given ? geometry::ScaleRuleFromString(a.scale, "--scale")
                              : (outline.from_image ? geometry::ScaleRule::Sternum(0.20)
                                                    : geometry::ScaleRule::None());
  options.front = front_given ? geometry::FrontAxisFromString(a.front, "--front")
                              : outline.front.value_or(geometry::FrontAxis::kPlusY);
  const Body body = geometry::BuildBody(outline, options);
  geometry::WriteBodyJson(body, a.output);
  std::printf("%s", geometry::BodyReport(body).c_str());
  std::printf("wrote %s\n", a.output.c_str());
  if (!a.picture.empty()) {
    DrawBodyPicture(body, "body from " + a.outline, a.picture);
    std::printf("wrote %s\n", a.picture.c_str());
  }
}

// --- population ----------------------------------------------------------------

struct PopulationArgs {
  std::string mode = "paper", output, picture;
  std::string body = "venues/bodies/thorax-18.json";
  std::string anthropometry = geometry::kAnsurExtractPath;
  std::size_t count = 100;
  std::uint64_t seed = 1;
  double female_fraction = 0.5;
  bool force = false;
};

void RunPopulation(const PopulationArgs& a) {
  CheckOutputs({{"-o", a.output, geometry::PopulationJsonOutput()}, {"--picture", a.picture, PictureOutputKind()}},
               {{"the reference body", a.body}, {"the anthropometry extract", a.anthropometry}}, a.force);
  geometry::PopulationOptions options;
  options.mode = geometry::PopulationModeFromString(a.mode, "--mode");
  options.count = a.count;
  options.seed = a.seed;
  options.female_fraction = a.female_fraction;
  std::vector<geometry::AnsurRecord> records;
  // The paper and circle modes scale the reference body; the circle mode only
  // needs its area, but reading it keeps the two modes' masses and areas tied.
  std::optional<Body> reference;
  if (options.mode == geometry::PopulationMode::kAnthropometric) {
    records = geometry::ReadAnsurExtract(a.anthropometry);
  } else {
    reference = geometry::ReadBodyJson(a.body);
  }
  const Spheropolygon fallback = Spheropolygon::Create({{0.0, 0.0}}, 0.1);
  const auto start = std::chrono::steady_clock::now();
  const geometry::Population population =
      geometry::MakePopulation(options, reference ? reference->shape : fallback, records);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  geometry::WritePopulationJson(population, a.output);

  double m_lo = std::numeric_limits<double>::infinity(), m_hi = 0, m_sum = 0;
  double a_lo = m_lo, a_hi = 0;
  for (const geometry::Person& p : population.people) {
    m_lo = std::min(m_lo, p.mass_kg);
    m_hi = std::max(m_hi, p.mass_kg);
    m_sum += p.mass_kg;
    a_lo = std::min(a_lo, p.shape.area());
    a_hi = std::max(a_hi, p.shape.area());
  }
  std::printf("population: %s, %zu people, seed %llu\n", a.mode.c_str(), population.people.size(),
              static_cast<unsigned long long>(a.seed));
  std::printf("mass: %.2f .. %.2f kg (mean %.2f)\narea: %.5f .. %.5f m^2\n", m_lo, m_hi,
              m_sum / static_cast<double>(population.people.size()), a_lo, a_hi);
  if (options.mode == geometry::PopulationMode::kAnthropometric)
    std::printf("bodies built: %zu distinct (%zu with a reduced sphero-radius)\n",
                population.distinct_shapes, population.reduced_radius);
  std::printf("time: %.3f s\nwrote %s\n", seconds, a.output.c_str());
  if (!a.picture.empty()) {
    DrawPopulationPicture(population, a.picture);
    std::printf("wrote %s\n", a.picture.c_str());
  }
}

// --- body reference --------------------------------------------------------------

struct ReferenceArgs {
  std::string anthropometry = geometry::kAnsurExtractPath;
  std::string outline = "venues/bodies/thorax-reference.json";
  std::string output = "venues/bodies/thorax-18.json";
  std::string picture;
  double female_fraction = 0.5;
  std::size_t vertices = 18;
  double radius_m = 0.05;
  bool force = false;
};

void RunReference(const ReferenceArgs& a) {
  CheckOutputs({{"--outline", a.outline, geometry::OutlineJsonOutput()},
                {"-o", a.output, geometry::BodyJsonOutput()},
                {"--picture", a.picture, PictureOutputKind()}},
               {{"the anthropometry extract", a.anthropometry}}, a.force);
  const auto records = geometry::ReadAnsurExtract(a.anthropometry);
  const geometry::ThoraxDimensions d = geometry::MedianThoraxDimensions(records, a.female_fraction);
  const geometry::ThoraxModel model;
  geometry::Outline outline;
  outline.source = a.outline;
  outline.front = geometry::FrontAxis::kPlusX;
  outline.points = geometry::ThoraxOutline(d, model);
  char text[512];
  std::snprintf(text, sizeof text,
                "Reference thorax with arms (metres, chest facing +x), made by `crowdrecon body "
                "reference` from ANSUR II medians with female fraction %g: chest breadth %.3f, "
                "chest depth %.3f, bideltoid breadth %.3f (biacromial %.3f); torso superellipse "
                "n=%g, arm overlap %.3f m, arm depth %.2f x chest depth. See docs/bodies.md.",
                a.female_fraction, d.chest_breadth_m, d.chest_depth_m, d.bideltoid_breadth_m,
                d.biacromial_breadth_m, model.superellipse_exponent, model.arm_overlap_m,
                model.arm_depth_fraction);
  outline.description = text;
  geometry::WriteOutlineJson(outline, a.outline);
  std::printf("%s\nwrote %s (%zu points)\n", text, a.outline.c_str(), outline.points.size());

  // Rebuilt from the file just written, as `crowdrecon shape` would.
  const geometry::Outline reread = geometry::ReadOutlinePoints(a.outline);
  geometry::BodyOptions options;
  options.vertex_count = a.vertices;
  options.radius_m = a.radius_m;
  options.front = reread.front.value_or(geometry::FrontAxis::kPlusX);
  const Body body = geometry::BuildBody(reread, options);
  geometry::WriteBodyJson(body, a.output);
  std::printf("%swrote %s\n", geometry::BodyReport(body).c_str(), a.output.c_str());
  if (!a.picture.empty()) {
    DrawBodyPicture(body, "reference thorax (ANSUR II medians, " + FormatNumber(100 * a.female_fraction) +
                              "% female)", a.picture);
    std::printf("wrote %s\n", a.picture.c_str());
  }
}

}  // namespace

void RegisterShapeCommands(CLI::App& app) {
  {
    auto args = std::make_shared<ShapeArgs>();
    CLI::App* cmd = app.add_subcommand(
        "shape", "Build a spheropolygon body from an outline (image or point list)");
    cmd->add_option("outline", args->outline,
                    "Outline: image (.png, ...; largest dark/light region) or points (.json, .csv)")
        ->required();
    cmd->add_option("-o,--output", args->output, "Body JSON to write")->required();
    cmd->add_option("--vertices", args->vertices, "Vertices of the core polygon")
        ->capture_default_str()
        ->check(IntegerIn(3, 1000));
    cmd->add_option("--radius", args->radius_m, "Sphero-radius, m")->capture_default_str()->check(NumberIn(1e-4, 1.0, "m"));
    CLI::Option* scale = cmd->add_option(
        "--scale", args->scale,
        "sternum:DEPTH_M | shoulder:WIDTH_M | ppm:PIXELS_PER_M | none "
        "(default: sternum:0.20 for images, none = metres for point lists)");
    CLI::Option* front = cmd->add_option(
        "--front", args->front, "+y|-y|+x|-x: where the chest faces in the outline (default +y)");
    cmd->add_option("--region", args->region, "dark|light: which image region is the body")
        ->capture_default_str();
    cmd->add_option("--picture", args->picture, "Picture to draw (.png, .svg, .pdf)");
    AddForceFlag(cmd, &args->force);
    cmd->callback([args, scale, front] { RunShape(*args, scale->count() > 0, front->count() > 0); });
  }
  {
    auto args = std::make_shared<PopulationArgs>();
    CLI::App* cmd = app.add_subcommand("population", "Draw a population of bodies with masses");
    cmd->add_option("--mode", args->mode, "paper | anthropometric | circle")->capture_default_str();
    // Ranges from the population table (geometry/population_table.hpp), as in scenarios.
    const auto in_table = [](std::string_view path) {
      const geometry::PopulationKeyInfo& k = geometry::PopulationKey(path);
      return k.integer ? IntegerIn(static_cast<long long>(k.min), static_cast<long long>(k.max))
                       : NumberIn(k.min, k.max, k.unit);
    };
    cmd->add_option("--count", args->count, "Number of people")->capture_default_str()->check(in_table("count"));
    cmd->add_option("--seed", args->seed, "Random seed")->capture_default_str()->check(in_table("seed"));
    cmd->add_option("--female-fraction", args->female_fraction,
                    "Anthropometric mode: fraction of women")
        ->capture_default_str()
        ->check(in_table("body.female_fraction"));
    cmd->add_option("--body", args->body, "Reference body (paper, circle modes)")->capture_default_str();
    cmd->add_option("--anthropometry", args->anthropometry, "ANSUR II extract (anthropometric mode)")
        ->capture_default_str();
    cmd->add_option("-o,--output", args->output, "Population JSON to write")->required();
    cmd->add_option("--picture", args->picture, "Picture of the first bodies (.png, .svg, .pdf)");
    AddForceFlag(cmd, &args->force);
    cmd->callback([args] { RunPopulation(*args); });
  }
  {
    CLI::App* body = app.add_subcommand("body", "Reference bodies");
    body->require_subcommand(1);
    auto args = std::make_shared<ReferenceArgs>();
    CLI::App* cmd = body->add_subcommand(
        "reference", "Write the reference thorax outline (ANSUR II medians) and its body");
    cmd->add_option("--anthropometry", args->anthropometry, "ANSUR II extract")->capture_default_str();
    cmd->add_option("--female-fraction", args->female_fraction, "Fraction of women in the medians")
        ->capture_default_str()
        ->check(NumberIn(0.0, 1.0));
    cmd->add_option("--vertices", args->vertices, "Vertices of the core polygon")
        ->capture_default_str()
        ->check(IntegerIn(3, 1000));
    cmd->add_option("--radius", args->radius_m, "Sphero-radius, m")->capture_default_str()->check(NumberIn(1e-4, 1.0, "m"));
    cmd->add_option("--outline", args->outline, "Outline JSON to write")->capture_default_str();
    cmd->add_option("-o,--output", args->output, "Body JSON to write")->capture_default_str();
    cmd->add_option("--picture", args->picture, "Picture to draw (.png, .svg, .pdf)");
    AddForceFlag(cmd, &args->force);
    cmd->callback([args] { RunReference(*args); });
  }
}

}  // namespace crowdrecon::cli
