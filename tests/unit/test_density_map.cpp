// Density maps (issue 20): a kernel estimate whose integral is the number of
// people, uniform where people are spread uniformly.
#include <gtest/gtest.h>

#include <vector>

#include "crowdrecon/analysis/density_map.hpp"

namespace crowdrecon::analysis {
namespace {

TEST(DensityMap, IntegratesToThePeopleAndReadsAUniformCrowd) {
  // A lattice of 2 persons/m2 (0.5 m x 1 m spacing) over 20 m x 10 m.
  std::vector<Vec2> people;
  for (double x = 0.25; x < 20.0; x += 0.5)
    for (double y = 0.5; y < 10.0; y += 1.0) people.push_back({x, y});
  const DensityMap m = DensityOf(people, {-5.0, -5.0}, {25.0, 15.0}, 0.25, 0.5);
  double integral = 0.0;
  for (double d : m.density_per_m2) integral += d * m.cell_m * m.cell_m;
  EXPECT_NEAR(integral, double(people.size()), 1e-3 * double(people.size()));
  // In the middle, far from the edges: 2 /m2 (the kernel smooths the lattice).
  const std::size_t ix = static_cast<std::size_t>((10.0 + 5.0) / m.cell_m), iy = static_cast<std::size_t>((5.0 + 5.0) / m.cell_m);
  EXPECT_NEAR(m.At(ix, iy), 2.0, 0.02);
  EXPECT_EQ(m.people, people.size());
  // Outside the crowd, beyond the kernel's reach: empty.
  EXPECT_EQ(m.At(1, 1), 0.0);
  DensityMapOptions bad;
  bad.cell_m = 0.0;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("cell = 0 m"), std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::analysis
