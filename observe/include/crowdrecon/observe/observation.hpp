// Observations: what was seen of a crowd, in one format whatever the source --
// trajectories of an experiment, footage of an incident, or a simulated run --
// so that a calibration compares like with like (docs/observations.md).
//
//   observe::ObservationSpec spec = observe::ReadObservationSpec("hallway.json");
//   observe::Observation obs = observe::ObserveTrajectories(observe::ReadTrajectories("run.sqlite"), spec);
//   observe::WriteObservation(obs, "run.observation.json");   // and run.observation.csv
//
// An observation holds its source (file, SHA-256, method, options), the
// regions and lines of the spec in venue coordinates, binned time series with
// uncertainties, and events (stops and surges) with times and uncertainties.
// Every series is per direction of travel along the spec's axis: "forward"
// (along the axis) and "backward" (against it).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/observe/events.hpp"
#include "crowdrecon/observe/trajectories.hpp"

namespace crowdrecon::observe {

struct Region {
  std::string name;
  std::vector<Vec2> polygon_m;  // a simple polygon, either orientation
  double Area_m2() const;
  bool Contains(Vec2 p) const;
};

struct Line {
  std::string name;
  Vec2 a_m, b_m;
  double Length_m() const { return Length(b_m - a_m); }
};

// What to measure: a file (JSON, docs/observations.md) or built in code.
struct ObservationSpec {
  // Direction of "forward" travel (normalised when read), e.g. along the
  // hallway toward its exit.
  Vec2 axis{1.0, 0.0};
  std::vector<Region> regions;  // at least one
  std::vector<Line> lines;      // may be empty
  // Width of the time bins of every series (s): the paper read velocities
  // from frames 0.2 s apart, and an onset must be placed within a second.
  double bin_s = 0.2;
  // Span of a velocity (s): positions (or images) this far apart: the
  // paper's 0.2 s, several frames at 25 fps, so that tracking jitter of a
  // few centimetres is a few tenths of m/s at most.
  double velocity_span_s = 0.2;
  // A sample moves along a direction when its velocity along the axis
  // exceeds this (m/s); below it, it is still: the same tenth of the
  // desired speed as the analysis' stop threshold (docs/analysis.md).
  double still_speed_m_per_s = 0.1;
  // Floor area one person covers seen from above (m2): a trajectory sample
  // stands for this much floor, and in footage the grid points within it
  // move together (standard errors count them as one sample).
  double person_area_m2 = 0.1;
  // A direction's speed in a bin is defined only when the floor moving that
  // way (movers x person_area_m2 for trajectories, moving grid points x
  // their cell for footage; per frame) is at least this; below it the
  // direction counts as stopped (speed 0), so that a few people jostled in a
  // standing crowd are not read as the direction walking. An area, not a
  // share, so that trajectories (shares of people) and footage (shares of
  // floor) agree: 0.25 m2 is two or three people.
  double min_moving_area_m2 = 0.25;
  EventOptions events;

  bool IsValid(std::string* error) const;
};

// Reads a spec file; an InputError names the file, the JSON path, the value
// and what was expected.
ObservationSpec ReadObservationSpec(const std::filesystem::path& file);
ObservationSpec ParseObservationSpec(const std::string& text, const std::string& source);
std::string SpecToJson(const ObservationSpec& spec);

// One value of a series with its uncertainty (standard error of the bin's
// mean unless the quantity says otherwise) and the number of samples behind it.
struct SeriesPoint {
  double value = 0.0;        // NaN where the quantity is undefined in the bin
  double uncertainty = 0.0;  // NaN with it
  double samples = 0.0;
};

// A time series: `quantity` of `where` (a region's or line's name) for a
// direction ("forward", "backward" or "all"), in `unit`, one point per bin;
// bin k covers [t0 + k bin_s, t0 + (k+1) bin_s).
struct Series {
  std::string quantity;   // speed, share_moving, share_still, counterflow_share, mean_velocity, max_speed, density, flow
  std::string where;
  std::string direction;  // forward, backward, all
  std::string unit;
  std::vector<SeriesPoint> points;
};

struct Observation {
  // Source: the file observed, its checksum, how it was observed and with
  // which options (the spec and the method's own options, as JSON).
  std::string source_file;
  std::string source_sha256;
  std::string source_format;  // petrack, jupedsim-v2, crowdrecon-run, video
  std::string method;         // "trajectories" or "footage"
  std::string method_options_json = "{}";
  ObservationSpec spec;
  double t0_s = 0.0;          // start of the first bin
  double bin_s = 0.0;
  std::size_t bins = 0;
  std::vector<Series> series;
  std::vector<Event> events;
  std::vector<std::string> notes;

  const Series* Find(const std::string& quantity, const std::string& where, const std::string& direction) const;
  std::vector<double> BinTimes() const;  // centres of the bins
};

// Observes trajectories: samples are person-frames (docs/observations.md):
//   speed (forward/backward): mean of |v.axis| over the samples moving that way;
//   share_moving (forward/backward) and share_still: shares of the samples
//     in the region (of the people in it);
//   counterflow_share: backward movers / all movers;
//   mean_velocity (all): mean v.axis over every sample;
//   max_speed (all): the largest |v.axis| among the samples;
//   density (all): classic density, people in the region / its area;
//   flow (forward/backward) per line: crossings per second per metre.
// Events from the speed series (events.hpp), per region and direction.
Observation ObserveTrajectories(const Trajectories& trajectories, const ObservationSpec& spec);

// Writes the observation as JSON (metadata, regions, lines, events, and the
// series' names) and its series as CSV beside it (same name, .csv): columns
// time_s, quantity, where, direction, unit, value, uncertainty, samples.
// The JSON records the CSV's SHA-256. Both are written complete to
// temporary names before either is renamed in place (a full disk leaves a
// previous pair whole). Returns the partial files of killed writers of the
// pair that it removed, for the command to say so.
std::vector<std::filesystem::path> WriteObservation(const Observation& observation,
                                                    const std::filesystem::path& json_file);
// Reads what WriteObservation wrote (checks the CSV against its checksum).
Observation ReadObservation(const std::filesystem::path& json_file);
// The CSV beside an observation file (same name, .csv).
std::filesystem::path ObservationCsvPath(const std::filesystem::path& json_file);
// The series file that an existing observation file names (its
// "series_file"), or ObservationCsvPath where it names none or cannot be
// read: with the JSON, what a command that reads the observation must never
// overwrite (common/output_path.hpp).
std::filesystem::path ObservationSeriesPath(const std::filesystem::path& json_file);
// Previous outputs, which observe -o may replace (common/output_path.hpp).
OutputKind ObservationJsonOutput();
OutputKind ObservationCsvOutput();

}  // namespace crowdrecon::observe
