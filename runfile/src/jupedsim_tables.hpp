// Internal: what every JuPedSim trajectory file this library writes shares --
// the run file (run_file_writer.cpp) and the plain export (trajectory_export.cpp):
// JuPedSim's version-2 tables, the geometry hash and how numbers are stored
// as metadata text. One source, so that both stay what PedPy reads.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "crowdrecon/common/fnv.hpp"

namespace crowdrecon::runfile::detail {

// JuPedSim's trajectory format, version 2 (PedPy's
// load_trajectory_from_jupedsim_sqlite and load_walkable_area_from_jupedsim_sqlite).
inline constexpr const char* kJuPedSimSchema = R"SQL(
CREATE TABLE trajectory_data(frame INTEGER NOT NULL, id INTEGER NOT NULL, pos_x REAL NOT NULL,
  pos_y REAL NOT NULL, ori_x REAL NOT NULL, ori_y REAL NOT NULL);
CREATE TABLE metadata(key TEXT NOT NULL UNIQUE PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE geometry(hash INTEGER NOT NULL, wkt TEXT NOT NULL);
CREATE TABLE frame_data(frame INTEGER NOT NULL, geometry_hash INTEGER NOT NULL);
)SQL";

// A number as metadata text, exactly (17 significant digits).
inline std::string NumberText(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// 64-bit FNV-1a of the WKT, as the geometry hash (JuPedSim uses Python's hash;
// any integer identifying the geometry will do for readers).
inline std::int64_t GeometryHash(const std::string& wkt) {
  return static_cast<std::int64_t>(Fnv1a(wkt.data(), wkt.size()) >> 1);
}

}  // namespace crowdrecon::runfile::detail
