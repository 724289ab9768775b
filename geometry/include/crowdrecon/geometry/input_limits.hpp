// Limits on geometry inputs (body outlines, floor plans). An input beyond one
// of them is refused before any work is done, with the limit and the likely
// cause, because the work (and memory) grows with the input and an input this
// large is nearly always a wrong unit or resolution, not a wish. Every reader
// and every message takes the numbers from here (docs/bodies.md and
// docs/venues.md quote them).
#pragma once

#include <cstddef>

namespace crowdrecon::geometry {

// Pixels of a picture (body outline, raster floor plan), width x height.
// 100 megapixels: a body traced at 10 px/mm, or a 200 m x 200 m floor plan at
// 50 px/m. Decoding costs about 1 byte a pixel per working copy.
inline constexpr double kMaxImagePixels = 1e8;

// Magnitude of a body outline's coordinates, in the file's own units (metres,
// millimetres, pixels). Beyond this the squares of coordinates lose every
// digit that matters (and overflow near 1e154), and no unit makes a body
// this large.
inline constexpr double kMaxOutlineCoordinate = 1e9;

// Largest extent (width or depth) of a body outline once in metres. A body
// is 0.2-1 m across; 3 m leaves room for a person with outstretched arms.
inline constexpr double kMaxBodyExtentM = 3.0;

// Entities of a DXF floor plan after every block INSERT (and MINSERT array)
// is expanded, and the points they hold once curves are flattened.
inline constexpr std::size_t kMaxDxfEntities = 20000;
inline constexpr std::size_t kMaxDxfPoints = 1000000;

}  // namespace crowdrecon::geometry
