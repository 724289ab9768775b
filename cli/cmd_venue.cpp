// `crowdrecon venue check` and `crowdrecon venue import`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/navigation.hpp"
#include "crowdrecon/geometry/capacity.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/viz/draw_venue.hpp"

namespace crowdrecon::cli {

namespace {

namespace geo = crowdrecon::geometry;

std::string VecText(Vec2 v) { return "(" + FormatNumber(v.x) + ", " + FormatNumber(v.y) + ")"; }

struct CheckArgs {
  std::string file;
  std::string picture;
  double grid_spacing_m = 0.1;
  bool force = false;
};

void RunCheck(const CheckArgs& args) {
  CheckOutputs({{"--picture", args.picture, PictureOutputKind()}}, {{"the venue", args.file}}, args.force);
  const geo::Venue v = geo::LoadVenue(args.file);
  geo::NavigationOptions nav;
  nav.grid_spacing_m = args.grid_spacing_m;
  if (std::string error; !nav.IsValid(&error)) throw InputError("navigation: " + error);

  const double area = geo::WalkableArea_m2(v);
  std::printf("venue: %s  [%s]\n", v.metadata.name.c_str(), args.file.c_str());
  if (!v.metadata.source.empty()) std::printf("  source: %s\n", v.metadata.source.c_str());
  std::printf("  walkable area: %s m2 in %zu part(s), perimeter %s m\n", FormatFixed(area, 2).c_str(),
              v.walkable_area.size(), FormatFixed(geo::WalkablePerimeter_m(v), 2).c_str());
  double wall_length = 0.0;
  const auto segments = geo::WallSegments(v);
  for (const geo::WallSegment& s : segments) wall_length += Length(s.b - s.a);
  std::printf("  walls: %zu (%zu segments, %s m, exit openings cut out), obstacles: %zu\n", v.walls.size(),
              segments.size(), FormatFixed(wall_length, 2).c_str(), v.obstacles.size());
  std::printf("  exits: %zu\n", v.exits.size());
  for (const geo::Exit& e : v.exits) {
    // The longest walk to each exit also reveals parts that cannot reach it.
    const geo::NavigationField field = geo::NavigationField::ToExit(v, e.id, nav);
    double farthest = 0.0;
    for (double t : field.distance_m())
      if (std::isfinite(t)) farthest = std::max(farthest, t);
    // Walkable grid nodes the front never reached (away from walls, where
    // nodes are cut off by design) reveal parts from which the exit is walled off.
    std::size_t unreachable = 0;
    for (std::size_t j = 0; j < field.ny(); ++j)
      for (std::size_t i = 0; i < field.nx(); ++i) {
        if (std::isfinite(field.distance_m()[j * field.nx() + i])) continue;
        const Vec2 p = field.origin_m() + field.spacing_m() * Vec2{static_cast<double>(i), static_cast<double>(j)};
        if (!geo::IsWalkable(v, p)) continue;
        double clearance = std::numeric_limits<double>::infinity();
        for (const geo::WallSegment& s : segments) clearance = std::min(clearance, DistanceToSegment(p, s.a, s.b));
        if (clearance > 1.5 * field.spacing_m()) ++unreachable;
      }
    std::printf("    %-16s free width %s m, from %s to %s; longest walk to it %s m%s\n", e.id.c_str(),
                FormatFixed(v.FreeWidth_m(e), 2).c_str(), VecText(e.a).c_str(), VecText(e.b).c_str(),
                FormatFixed(farthest, 1).c_str(),
                unreachable > 0 ? (", " + std::to_string(unreachable) + " grid nodes cannot reach it").c_str() : "");
  }
  std::printf("  entries: %zu\n", v.entries.size());
  for (const geo::EntryZone& e : v.entries)
    std::printf("    %-16s %s m2\n", e.id.c_str(), FormatFixed(std::abs(geo::RingSignedArea_m2(e.polygon)), 2).c_str());
  std::printf("  measurement areas: %zu, lines: %zu\n", v.measurement_areas.size(), v.measurement_lines.size());
  if (v.periodic.empty()) std::printf("  periodic: none\n");
  for (const geo::PeriodicDirection& p : v.periodic)
    std::printf("  periodic: along %s, period %s m\n", VecText(p.direction).c_str(), FormatNumber(p.period_m).c_str());
  for (const geo::Target& t : v.targets)
    std::printf("  target %-16s %s\n", t.id.c_str(),
                t.kind == geo::Target::Kind::kExit
                    ? (t.exit_ids.size() > 1 ? "the nearest of " + std::to_string(t.exit_ids.size()) + " exits"
                                             : "exit \"" + t.exit_id + "\"").c_str()
                                                   : ("direction " + VecText(t.direction)).c_str());
  if (v.slope)
    std::printf("  slope: gradient %s (%s %%, %s degrees) downhill toward %s, %s, %s\n", FormatNumber(v.slope->gradient).c_str(),
                FormatFixed(100.0 * v.slope->gradient, 1).c_str(),
                FormatFixed(std::atan(v.slope->gradient) * 180.0 / std::numbers::pi, 1).c_str(),
                VecText(v.slope->direction).c_str(), v.slope->enabled ? "enabled" : "disabled",
                v.slope->region.empty() ? "the whole floor"
                                        : ("inside a region of " + std::to_string(v.slope->region.size()) + " points").c_str());
  else
    std::printf("  slope: none (level floor)\n");
  const geo::Capacity capacity = geo::VenueCapacity(v);
  std::printf("  capacity: %.0f persons at %.1f /m2, %.0f at %.1f /m2\n", capacity.at_guidance,
              geo::kGuidanceDensity_per_m2, capacity.at_danger, geo::kDangerDensity_per_m2);

  if (!args.picture.empty()) {
    viz::VenuePictureOptions picture;
    geo::NavigationField field = geo::NavigationField::Constant({0, 0});
    if (!v.exits.empty()) {
      field = geo::NavigationField::ToExit(v, v.exits.front().id, nav);
      picture.field = &field;
      picture.field_label = "direction to exit \"" + v.exits.front().id + "\"";
    } else if (!v.targets.empty()) {
      field = geo::NavigationField::ForTarget(v, v.targets.front().id, nav);
      picture.field = &field;
      picture.field_label = "direction of target \"" + v.targets.front().id + "\"";
    }
    viz::DrawVenue(v, args.picture, picture);
    std::printf("  picture: %s\n", args.picture.c_str());
  }
  std::printf("venue OK\n");
}

struct ImportArgs {
  std::string input;
  std::string output;
  std::string format;
  double pixels_per_metre = 0.0;
  int dark_threshold = 128;
  std::string seed;
  std::string name;
  std::string layer;
  double scale_m_per_unit = 0.0;
  double simplify_px = 0.75;
  bool force = false;
};

std::string FormatFromExtension(const std::string& input) {
  std::string ext = std::filesystem::path(input).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".wkt") return "wkt";
  if (ext == ".dxf") return "dxf";
  for (const char* image : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".pbm"})
    if (ext == image) return "image";
  throw InputError(input + ": cannot tell the format from the extension \"" + ext +
                   "\"; expected .wkt, .dxf or an image, or give --format wkt|dxf|image");
}

Vec2 ParseSeed(const std::string& text) {
  const auto comma = text.find(',');
  try {
    if (comma == std::string::npos) throw std::invalid_argument("no comma");
    std::size_t used_x = 0, used_y = 0;
    const std::string xs = text.substr(0, comma), ys = text.substr(comma + 1);
    const double x = std::stod(xs, &used_x), y = std::stod(ys, &used_y);
    if (used_x != xs.size() || used_y != ys.size()) throw std::invalid_argument("trailing text");
    return {x, y};
  } catch (const std::exception&) {
    throw InputError("--seed \"" + text + "\": expected two numbers X,Y in metres (e.g. --seed 5,2)");
  }
}

void RunImport(const ImportArgs& args) {
  CheckOutputs({{"-o", args.output, geo::VenueJsonOutput()}}, {{"the floor plan", args.input}}, args.force);
  const std::string format = args.format.empty() ? FormatFromExtension(args.input) : args.format;
  geo::Venue venue;
  if (format == "image") {
    if (args.pixels_per_metre <= 0.0)
      throw InputError(args.input + ": importing an image needs its scale; give --pixels-per-metre N");
    geo::RasterImportOptions options;
    options.name = args.name;
    options.pixels_per_metre = args.pixels_per_metre;
    options.dark_threshold = args.dark_threshold;
    options.simplify_tolerance_px = args.simplify_px;
    if (!args.seed.empty()) options.seed_m = ParseSeed(args.seed);
    venue = geo::ImportRasterPlan(args.input, options);
  } else {
    geo::ImportOptions options;
    options.name = args.name;
    options.scale_m_per_unit = args.scale_m_per_unit;
    options.dxf_layer = args.layer;
    venue = format == "wkt" ? geo::ImportWkt(args.input, options) : geo::ImportDxf(args.input, options);
  }
  geo::WriteVenueJson(venue, args.output);
  std::printf("imported %s (%s): %s m2 walkable in %zu part(s), %zu obstacle(s), perimeter %s m\n",
              args.input.c_str(), format.c_str(), FormatFixed(geo::WalkableArea_m2(venue), 2).c_str(),
              venue.walkable_area.size(), venue.obstacles.size(), FormatFixed(geo::WalkablePerimeter_m(venue), 2).c_str());
  std::printf("wrote %s (add exits, entries and targets by hand, then run `crowdrecon venue check`)\n",
              args.output.c_str());
}

}  // namespace

void RegisterVenueCommands(CLI::App& app) {
  CLI::App* venue = app.add_subcommand("venue", "Venues: check a venue file, import floor plans");
  venue->require_subcommand(1);

  auto check_args = std::make_shared<CheckArgs>();
  CLI::App* check = venue->add_subcommand("check", "Validate a venue file, print a summary, draw a picture");
  check->add_option("FILE", check_args->file, "venue file (JSON, see docs/venues.md)")->required();
  check->add_option("--picture", check_args->picture, "write a picture of the venue (.png, .svg or .pdf)");
  check->add_option("--grid-spacing", check_args->grid_spacing_m,
                    "grid spacing of the navigation field in metres (default 0.1)")
      ->check(NumberIn(0.005, 10.0, "m"));
  AddForceFlag(check, &check_args->force);
  check->callback([check_args] { RunCheck(*check_args); });

  auto import_args = std::make_shared<ImportArgs>();
  CLI::App* import = venue->add_subcommand("import", "Convert a WKT, DXF or raster floor plan to a venue file");
  import->add_option("INPUT", import_args->input, "floor plan: .wkt, .dxf or an image")->required();
  import->add_option("-o,--output", import_args->output, "venue file to write (JSON)")->required();
  import->add_option("--format", import_args->format, "input format (default: from the extension)")
      ->check(CLI::IsMember({"wkt", "dxf", "image"}));
  import->add_option("--pixels-per-metre", import_args->pixels_per_metre, "image scale (required for images)")
      ->check(NumberIn(1e-3, 1e6, "pixels per metre"));
  import->add_option("--dark-threshold", import_args->dark_threshold,
                     "image: grey levels below this are walls (1-255, default 128)")
      ->check(IntegerIn(1, 255));
  import->add_option("--seed", import_args->seed,
                     "image: X,Y in metres (from the lower-left corner) inside the wanted region");
  import->add_option("--name", import_args->name, "venue name (default: the input's file name)");
  import->add_option("--layer", import_args->layer, "DXF: import this layer only");
  import->add_option("--scale", import_args->scale_m_per_unit,
                     "WKT/DXF: metres per drawing unit (default: DXF $INSUNITS, else 1)")
      ->check(NumberIn(1e-9, 1e9, "m per unit"));
  import->add_option("--simplify-px", import_args->simplify_px,
                     "image: contour simplification tolerance in pixels (default 0.75)")
      ->check(NumberIn(0.0, 100.0, "px"));
  AddForceFlag(import, &import_args->force);
  import->callback([import_args] { RunImport(*import_args); });
}

}  // namespace crowdrecon::cli
