// The CUDA force computation (WorldDef::device = kCuda): the same results as
// the processor's, bit for bit, where a build has CUDA and a device; a clear
// refusal where it has not. The comparisons run only on a machine with a CUDA
// device (skipped elsewhere, with the reason).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using testing::RandomGas;

bool Same(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }
bool Same(Vec2 a, Vec2 b) { return Same(a.x, b.x) && Same(a.y, b.y); }

// Every field of every contact, and every body's state, bit for bit.
void ExpectSameRun(const Simulation& cpu, const Simulation& gpu, const std::string& where) {
  const BodyState& a = cpu.bodies();
  const BodyState& b = gpu.bodies();
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(Same(a.position_m[i], b.position_m[i])) << where << ": position of person " << i + 1;
    ASSERT_TRUE(Same(a.angle_rad[i], b.angle_rad[i])) << where << ": angle of person " << i + 1;
    ASSERT_TRUE(Same(a.velocity_m_per_s[i], b.velocity_m_per_s[i])) << where << ": velocity of person " << i + 1;
    ASSERT_TRUE(Same(a.contact_force_n[i], b.contact_force_n[i])) << where << ": contact force on person " << i + 1;
    ASSERT_TRUE(Same(a.contact_torque_n_m[i], b.contact_torque_n_m[i])) << where << ": torque on person " << i + 1;
  }
  const auto& ca = cpu.contacts();
  const auto& cb = gpu.contacts();
  ASSERT_EQ(ca.size(), cb.size()) << where;
  for (std::size_t k = 0; k < ca.size(); ++k) {
    const Contact& x = ca[k];
    const Contact& y = cb[k];
    ASSERT_TRUE(x.a == y.a && x.b == y.b && x.wall == y.wall && x.feature == y.feature) << where << ": contact " << k;
    ASSERT_TRUE(Same(x.point_m, y.point_m) && Same(x.normal, y.normal) && Same(x.overlap_m, y.overlap_m))
        << where << ": geometry of contact " << k;
    ASSERT_TRUE(Same(x.normal_force_n, y.normal_force_n) && Same(x.tangential_force_n, y.tangential_force_n) &&
                Same(x.tangential_spring_m, y.tangential_spring_m) && Same(x.viscous_normal_n, y.viscous_normal_n) &&
                Same(x.viscous_tangential_n, y.viscous_tangential_n) &&
                Same(x.trailing_fraction, y.trailing_fraction) && Same(x.leading_fraction, y.leading_fraction))
        << where << ": forces of contact " << k;
  }
}

bool CudaOrSkip(std::string* why) { return CudaAvailable(why); }

TEST(EngineCuda, RefusedWithAClearMessageWhereThereIsNone) {
  std::string why;
  if (CudaAvailable(&why)) GTEST_SKIP() << "this machine has CUDA: nothing to refuse";
  WorldDef def = RandomGas(3, 0.6, 1, true);
  def.device = ComputeDevice::kCuda;
  try {
    Simulation sim(def);
    FAIL() << "a CUDA run was accepted without CUDA";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("device: \"cuda\""), std::string::npos) << e.what();
    EXPECT_FALSE(why.empty());
  }
}

TEST(EngineCuda, SameResultsAsTheProcessorInADenseMixedCrowd) {
  std::string why;
  if (!CudaOrSkip(&why)) GTEST_SKIP() << why;
  // Thorax-like polygons (with their edge grids) and disks, periodic, with
  // the driving forces on: contacts made, held (tangential springs) and
  // broken; a person falls and one is removed mid-run; a checkpoint is
  // restored (the device then takes the contacts' history from the host).
  WorldDef def = RandomGas(30, 0.36, 11, true);
  def.parameters.ground_reaction = true;
  def.shapes.push_back(testing::DiskShape(0.2));
  for (std::size_t i = 0; i < def.people.size(); i += 5) {
    def.people[i].shape = 1;
    testing::SetMassFromShape(def.shapes[1], 1000.0, def.people[i]);
  }
  WorldDef gpu_def = def;
  gpu_def.device = ComputeDevice::kCuda;
  Simulation cpu(def), gpu(gpu_def);
  ExpectSameRun(cpu, gpu, "at t = 0");
  std::string checkpoint;
  for (int step = 1; step <= 600; ++step) {
    cpu.Step();
    gpu.Step();
    if (step == 150) {
      cpu.SetPersonState(17, PersonState::kFallen);
      gpu.SetPersonState(17, PersonState::kFallen);
      cpu.SetPersonState(300, PersonState::kRemoved);
      gpu.SetPersonState(300, PersonState::kRemoved);
    }
    if (step == 250) checkpoint = cpu.SaveState();
    if (step == 400) {
      cpu.LoadState(checkpoint);
      gpu.LoadState(checkpoint);
    }
    if (step % 50 == 0) ExpectSameRun(cpu, gpu, "step " + std::to_string(step));
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(cpu.contacts().size(), 512u);
  EXPECT_GE(cpu.profile().pair_rebuilds, 2u);
}

TEST(EngineCuda, SameResultsAsTheProcessorWithWalls) {
  std::string why;
  if (!CudaOrSkip(&why)) GTEST_SKIP() << why;
  // Person-wall pairs stay on the processor; their contacts follow the
  // device's in the list, as on the processor.
  WorldDef def = RandomGas(10, 0.42, 5, false);
  def.parameters.ground_reaction = true;
  def.walls.push_back({{{-0.3, -0.3}, {4.5, -0.3}, {4.5, 4.5}, {-0.3, 4.5}, {-0.3, -0.3}}, false, 0.1});
  WorldDef gpu_def = def;
  gpu_def.device = ComputeDevice::kCuda;
  gpu_def.threads = 2;
  Simulation cpu(def), gpu(gpu_def);
  bool walls_touched = false;
  for (int step = 1; step <= 800; ++step) {
    cpu.Step();
    gpu.Step();
    for (const Contact& c : cpu.contacts()) walls_touched = walls_touched || c.wall;
    if (step % 100 == 0) ExpectSameRun(cpu, gpu, "step " + std::to_string(step));
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_TRUE(walls_touched);
}

TEST(EngineCuda, AFailedDeviceHandsOverToTheProcessorWithTheSameResults) {
  std::string why;
  if (!CudaOrSkip(&why)) GTEST_SKIP() << why;
  // A device failure mid-run (injected after 60 evaluations): the run goes
  // on with the processor, says why, and its results are those of a run on
  // the processor throughout.
  WorldDef def = RandomGas(16, 0.38, 3, true);
  def.parameters.ground_reaction = true;
  WorldDef gpu_def = def;
  gpu_def.device = ComputeDevice::kCuda;
  setenv("CROWDRECON_CUDA_FAIL_AFTER", "60", 1);
  Simulation gpu(gpu_def);
  unsetenv("CROWDRECON_CUDA_FAIL_AFTER");
  Simulation cpu(def);
  for (int step = 1; step <= 200; ++step) {
    cpu.Step();
    gpu.Step();
    if (step == 40) {
      EXPECT_TRUE(gpu.device_fallback().empty());
    }
  }
  EXPECT_NE(gpu.device_fallback().find("injected"), std::string::npos) << gpu.device_fallback();
  EXPECT_NE(gpu.device_fallback().find("processor took over"), std::string::npos) << gpu.device_fallback();
  EXPECT_TRUE(cpu.device_fallback().empty());
  ExpectSameRun(cpu, gpu, "after the hand-over");
}

}  // namespace
}  // namespace crowdrecon::engine
