// World files: a complete engine world (WorldDef) as bytes. A world is
// prepared where the whole toolkit is installed (venue, population and
// navigation fields need CGAL, OpenCV and SQLite), saved, and run by the
// engine on a machine that has only a compiler and the engine's few
// dependencies. A Simulation built from the loaded world runs bit for bit as
// one built from the original.
//
// The format, in the machine's byte order (little-endian on every machine the
// project runs on; world_file.cpp refuses to build elsewhere):
//   "CRWORLD8"
//   the model parameters, in the order of the parameter table (parameter_table.hpp)
//     (doubles; enums as uint8; bools as uint8 0 or 1)
//   shapes  (count; per shape: vertices, radius_m, core_radius_m)
//   people  (count; per person: every field of PersonDef in order)
//   walls   (count; per wall: points, closed, radius_m)
//   targets (count; per field: constant flag, then the direction, or the
//            grid: origin, spacing, nx, ny, distances, directions)
//   periodic box, floor slope (downhill, gradient, region), threads (int32)
//   FNV-1a 64-bit checksum of everything before it, as in checkpoints.
// Counts are uint64; a list of numbers or points is its count followed by
// the values. Each field is written on its own (no structs with padding), so
// the bytes depend only on the world: SaveWorld(LoadWorld(SaveWorld(d))) ==
// SaveWorld(d). A change of WorldDef needs a new magic ("CRWORLD8").
#pragma once

#include <filesystem>
#include <string>

#include "crowdrecon/engine/world.hpp"

namespace crowdrecon::engine {

// The world as bytes (see above).
std::string SaveWorld(const WorldDef& def);

// The world saved by SaveWorld. `origin` (a file name, usually) begins every
// error message. Throws InputError if the data is not a world file, is
// damaged (checksum), cut short, or holds a value no world can have (an
// unknown enum value, a count larger than the data, an invalid navigation
// grid). The world itself is validated by the Simulation built from it.
WorldDef LoadWorld(const std::string& data, const std::string& origin);

// SaveWorld into a file. The bytes go to a temporary file beside it that is
// then renamed, so a failed or interrupted write leaves no partial world
// under `path`. Throws InputError naming the file if it cannot be written.
void SaveWorldFile(const WorldDef& def, const std::filesystem::path& path);

// LoadWorld from a file; errors begin with the file's name.
WorldDef LoadWorldFile(const std::filesystem::path& path);

}  // namespace crowdrecon::engine
