// World files (world_file.hpp). Each part of a world is listed once, in a
// function template that takes either the writer or the reader (the "Io"):
// the order of the fields on save and on load cannot then drift apart.
#include "crowdrecon/engine/world_file.hpp"

#include <bit>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "binary_io.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/engine/parameter_table.hpp"

namespace crowdrecon::engine {

namespace {

// Version 2: the parameter block follows the parameter table (five population
// fields that the engine never used left ModelParameters).
// Version 4: issue 39's parameters (gait jitter, yielding, creep of the tangential spring) at the table's end.
// Version 5: and the shoulder's turn and giving way after them.
// Version 6: the time step's mode and the adaptive step's parameters (issue 42), after time_step_safety.
// CRWORLD8: the drive's reaction time (issue 39) at the table's end.
// CRWORLD9: keeping a distance (issue 64: headway and its four numbers) at the table's end.
// CRWORLDA: the social force (issue 64: social_force and its three numbers) after them.
// CRWORLDB: the generalized centrifugal force (centrifugal and its eight numbers) and anticipation
// (anticipation and its four numbers) after them (issue 64).
// CRWORLDC: the anticipation's clock (issue 66: its interval and near radius) at the table's end.
// CRWORLDD: sleeping (issue 66: its speed, time and wake force) at the table's end.
// CRWORLDE: the anticipation's side preference (issue 64) at the table's end.
// CRWORLDF: and when it acts (anticipation_side_gate, a choice) after it.
constexpr char kWorldMagic[8] = {'C', 'R', 'W', 'O', 'R', 'L', 'D', 'F'};

// The bytes are the machine's; the development machine and the GPU machines
// are little-endian, so a file moves between them unchanged. A big-endian
// machine would need byte swapping here rather than wrong worlds.
static_assert(std::endian::native == std::endian::little, "world files are little-endian");
// Lists of points are copied as arrays: two doubles per point, no padding.
static_assert(sizeof(Vec2) == 2 * sizeof(double));
// Tripwires for the definition structs. A new field changes their size and
// stops the build here: add it to the Fields function below and change the
// magic (the old files would be read wrongly otherwise).
static_assert(sizeof(ModelParameters) == 544, "ModelParameters changed: update the parameter table (parameter_table.cpp) and the magic");
static_assert(sizeof(PersonDef) == 96, "PersonDef changed: update PersonFields and the magic");
static_assert(sizeof(PeriodicBox) == 40, "PeriodicBox changed: update the world file and the magic");
static_assert(sizeof(FloorSlope) == 48, "FloorSlope changed: update the world file and the magic");

class WorldWriter : public detail::BinaryWriter {
 public:
  WorldWriter() : BinaryWriter(kWorldMagic) {}

  void At(const char*, std::size_t) {}
  void Field(const double& v) { Put(v); }
  void Field(const std::uint32_t& v) { Put(v); }
  void Field(const int& v) { Put(static_cast<std::int32_t>(v)); }
  void Field(const Vec2& v) {
    Put(v.x);
    Put(v.y);
  }
  void Field(const std::vector<Vec2>& v) { PutVector(v); }
  void Field(const std::vector<double>& v) { PutVector(v); }
  void Count(std::size_t n) { Put(static_cast<std::uint64_t>(n)); }
  // One byte, whatever the size of the type in memory.
  void Flag(const bool& v, const char*) { Put(static_cast<std::uint8_t>(v ? 1 : 0)); }
  void Choice(const ModelParameters& p, const ParameterInfo& info) { Put(static_cast<std::uint8_t>(info.get_choice(p))); }
  template <typename E>
  void Enum(const E& v, E, const char*) {
    static_assert(std::is_enum_v<E>);
    Put(static_cast<std::uint8_t>(v));
  }
};

class WorldReader : public detail::BinaryReader {
 public:
  WorldReader(const std::string& data, const std::string& origin)
      : BinaryReader(data, kWorldMagic, origin + ": world file", "world") {}

  // The index of a part that is not an element of a list (the parameters).
  static constexpr std::size_t kWhole = std::numeric_limits<std::size_t>::max();

  // Where the fields that follow belong, for messages ("person 12").
  void At(const char* part, std::size_t index) {
    part_ = part;
    index_ = index;
  }
  void Field(double& v) { v = Get<double>(); }
  void Field(std::uint32_t& v) { v = Get<std::uint32_t>(); }
  void Field(int& v) { v = Get<std::int32_t>(); }
  void Field(Vec2& v) {
    v.x = Get<double>();
    v.y = Get<double>();
  }
  void Field(std::vector<Vec2>& v) { GetVector(v); }
  void Field(std::vector<double>& v) { GetVector(v); }
  std::size_t Count(std::size_t min_bytes_each) { return GetCount(min_bytes_each); }
  void Flag(bool& v, const char* name) {
    const auto byte = Get<std::uint8_t>();
    if (byte > 1) Bad(name, byte, "0 or 1");
    v = byte == 1;
  }
  void Choice(ModelParameters& p, const ParameterInfo& info) {
    const auto byte = Get<std::uint8_t>();
    if (byte >= info.choice_count) Bad(info.name, byte, "0 to " + std::to_string(info.choice_count - 1));
    info.set_choice(p, byte);
  }
  // Enumerators are numbered from 0 to `last` without gaps.
  template <typename E>
  void Enum(E& v, E last, const char* name) {
    const auto byte = Get<std::uint8_t>();
    const auto highest = static_cast<std::uint8_t>(last);
    if (byte > highest) Bad(name, byte, "0 to " + std::to_string(highest));
    v = static_cast<E>(byte);
  }

  // Wraps an error of a factory (a navigation field) with where it came from.
  [[noreturn]] void Invalid(const std::string& message) const { throw InputError(Where() + message); }

 private:
  [[noreturn]] void Bad(const char* name, unsigned value, const std::string& expected) const {
    Invalid(std::string(name) + " = " + std::to_string(value) + "; expected " + expected +
            " (a world file from another version of crowdrecon?)");
  }
  std::string Where() const {
    std::string where = name() + ": " + part_;
    if (index_ != kWhole) where += " " + std::to_string(index_);
    return where + ": ";
  }

  const char* part_ = "";
  std::size_t index_ = kWhole;
};

// --- the parts of a world, each listed once --------------------------------
// P is the part, const for the writer.

template <typename Io, typename P>
void ParameterFields(Io& io, P& p) {
  // Every parameter of the table (parameter_table.hpp), in its order.
  io.At("parameters", WorldReader::kWhole);
  for (const ParameterInfo& info : ModelParameterTable()) {
    switch (info.kind) {
      case ParameterInfo::Kind::kNumber: io.Field(p.*info.number); break;
      case ParameterInfo::Kind::kFlag: io.Flag(p.*info.flag, info.name); break;
      case ParameterInfo::Kind::kChoice: io.Choice(p, info); break;
    }
  }
}

template <typename Io, typename P>
void ShapeFields(Io& io, P& s) {
  io.Field(s.vertices);
  io.Field(s.radius_m);
  io.Field(s.core_radius_m);
}

template <typename Io, typename P>
void PersonFields(Io& io, P& p) {
  io.Field(p.position_m);
  io.Field(p.angle_rad);
  io.Field(p.velocity_m_per_s);
  io.Field(p.angular_velocity_rad_per_s);
  io.Field(p.mass_kg);
  io.Field(p.inertia_kg_m2);
  io.Field(p.shape);
  io.Field(p.desired_speed_m_per_s);
  io.Field(p.target);
  io.Field(p.group);
  io.Enum(p.state, PersonState::kRemoved, "state");
}

template <typename Io, typename P>
void WallFields(Io& io, P& w) {
  io.Field(w.points);
  io.Flag(w.closed, "closed");
  io.Field(w.radius_m);
}

template <typename Io, typename P>
void PeriodicFields(Io& io, P& b) {
  io.At("periodic box", WorldReader::kWhole);
  io.Flag(b.x, "x");
  io.Flag(b.y, "y");
  io.Field(b.min_m);
  io.Field(b.max_m);
}

template <typename Io, typename P>
void SlopeFields(Io& io, P& s) {
  io.Field(s.downhill);
  io.Field(s.gradient);
  io.Field(s.region);
}

// Bytes that one element of a list takes at the least (as the writer writes
// a default one: empty lists inside). A count read from a file is checked
// against the bytes left with it before anything is allocated.
template <typename T, typename Fields>
std::size_t SmallestSize(Fields fields) {
  WorldWriter w;
  const T empty{};
  fields(w, empty);
  return w.Finish().size() - sizeof(kWorldMagic) - sizeof(std::uint64_t);
}

// Reads a list of `T`, checking its count against the bytes left first.
template <typename T, typename Fields>
void ReadList(WorldReader& r, const char* part, std::vector<T>& list, Fields fields) {
  static const std::size_t smallest = SmallestSize<T>(fields);
  list.resize(r.Count(smallest));
  for (std::size_t i = 0; i < list.size(); ++i) {
    r.At(part, i);
    fields(r, list[i]);
  }
}

template <typename T, typename Fields>
void WriteList(WorldWriter& w, const std::vector<T>& list, Fields fields) {
  w.Count(list.size());
  for (const T& item : list) fields(w, item);
}

// Generic lambdas, so that one function serves the writer and the reader.
constexpr auto kShape = [](auto& io, auto& s) { ShapeFields(io, s); };
constexpr auto kPerson = [](auto& io, auto& p) { PersonFields(io, p); };
constexpr auto kWall = [](auto& io, auto& w) { WallFields(io, w); };

// A navigation field: the constant flag, then the direction or the grid.
// (Not a Fields function: a field is made by its factories, which validate
// what is read.)
void WriteTarget(WorldWriter& w, const geometry::NavigationField& f) {
  w.Flag(f.is_constant(), "constant");
  if (f.is_constant()) {
    w.Field(f.constant_direction());
    return;
  }
  w.Field(f.origin_m());
  w.Field(f.spacing_m());
  w.Put(static_cast<std::uint64_t>(f.nx()));
  w.Put(static_cast<std::uint64_t>(f.ny()));
  w.Field(f.distance_m());
  w.Field(f.direction());
}

geometry::NavigationField ReadTarget(WorldReader& r) {
  bool constant = true;
  r.Flag(constant, "constant");
  Vec2 direction, origin;
  double spacing = 0.0;
  std::uint64_t nx = 0, ny = 0;
  std::vector<double> distances;
  std::vector<Vec2> directions;
  if (constant) {
    r.Field(direction);
  } else {
    r.Field(origin);
    r.Field(spacing);
    nx = r.Get<std::uint64_t>();
    ny = r.Get<std::uint64_t>();
    r.Field(distances);
    r.Field(directions);
  }
  // The factories validate what was read; their messages get the file's name
  // and the target's index in front.
  try {
    // Exact: Constant would normalise the saved unit vector again, which may
    // move it by a rounding error.
    if (constant) return geometry::NavigationField::ConstantExact(direction);
    return geometry::NavigationField::FromGrid(origin, spacing, static_cast<std::size_t>(nx),
                                               static_cast<std::size_t>(ny), std::move(distances),
                                               std::move(directions));
  } catch (const InputError& e) {
    r.Invalid(e.what());
  }
}

}  // namespace

std::string SaveWorld(const WorldDef& def) {
  WorldWriter w;
  ParameterFields(w, def.parameters);
  WriteList(w, def.shapes, kShape);
  WriteList(w, def.people, kPerson);
  WriteList(w, def.walls, kWall);
  w.Count(def.targets.size());
  for (const geometry::NavigationField& f : def.targets) WriteTarget(w, f);
  PeriodicFields(w, def.periodic);
  SlopeFields(w, def.slope);
  w.Field(def.threads);
  w.Enum(def.device, ComputeDevice::kCuda, "device");
  return w.Finish();
}

WorldDef LoadWorld(const std::string& data, const std::string& origin) {
  WorldReader r(data, origin);
  WorldDef def;
  ParameterFields(r, def.parameters);
  ReadList(r, "shape", def.shapes, kShape);
  ReadList(r, "person", def.people, kPerson);
  ReadList(r, "wall", def.walls, kWall);
  // The smallest target is a constant one: the flag and a direction.
  def.targets.resize(r.Count(1 + sizeof(Vec2)));
  for (std::size_t k = 0; k < def.targets.size(); ++k) {
    r.At("target", k);
    def.targets[k] = ReadTarget(r);
  }
  PeriodicFields(r, def.periodic);
  SlopeFields(r, def.slope);
  r.Field(def.threads);
  r.Enum(def.device, ComputeDevice::kCuda, "device");
  // The checksum matched, so extra bytes were written on purpose by another
  // writer: refuse rather than ignore what we do not understand.
  if (r.remaining() != 0)
    throw InputError(r.name() + ": " + std::to_string(r.remaining()) +
                     " bytes after the world; expected none (a world file from another version of crowdrecon?)");
  return def;
}

void SaveWorldFile(const WorldDef& def, const std::filesystem::path& path) {
  const std::string data = SaveWorld(def);
  // Written beside the file and renamed over it: a rename within a directory
  // is atomic, so readers see the old file or the whole new one.
  std::filesystem::path partial = path;
  partial += ".partial";
  {
    errno = 0;
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (out) out.write(data.data(), static_cast<std::streamsize>(data.size()));
    if (out) out.close();
    if (!out) {
      const std::string reason = errno != 0 ? std::strerror(errno) : "write failed";
      std::error_code ignored;
      std::filesystem::remove(partial, ignored);
      throw InputError(path.string() + ": cannot write world file (" + reason + ")");
    }
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw InputError(path.string() + ": cannot write world file (" + ec.message() + ")");
  }
}

WorldDef LoadWorldFile(const std::filesystem::path& path) {
  return LoadWorld(ReadInputFile(path, "world file"), path.string());
}

}  // namespace crowdrecon::engine
