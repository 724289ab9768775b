// Reading a DXF floor plan's drawing (internal to geometry; dxf_drawing.cpp):
// its entities through dxflib, curves flattened into pieces, block inserts
// expanded (nested, scaled, rotated, mirrored, in arrays), in the file's
// units. venue_import_dxf.cpp chains the pieces into rings and decides what
// is walkable.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry::internal {

// One entity of the drawing as points.
struct DxfPiece {
  std::vector<Vec2> points;  // in file units
  bool closed = false;
  std::string layer;        // the entity's layer ("0" inside a block: the INSERT's)
  std::string unsupported;  // an entity that cannot be read, described: an error if it is wanted
};

struct DxfDrawing {
  std::vector<DxfPiece> pieces;
  double scale_m_per_unit = 1.0;  // metres per drawing unit ($INSUNITS, or the options' scale)
  std::size_t skipped_layers = 0; // entities on other layers than the options' one
};

// Reads `file` (an ASCII DXF file; a file cut short, or one dxflib cannot
// read, is an InputError naming it) on the options' layer, arcs flattened
// within the options' tolerance.
DxfDrawing ReadDxfDrawing(const std::filesystem::path& file, const ImportOptions& options);

}  // namespace crowdrecon::geometry::internal
