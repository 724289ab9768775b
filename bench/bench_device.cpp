// One whole Step() of a saved world on the processor and with the CUDA force
// computation (Google Benchmark), for machines that have a GPU but not the
// libraries that build worlds from scenarios (CGAL, OpenCV, SQLite): the
// worlds and their states come from files that `crowdrecon_bench_kernels
// --dump_worlds=DIR` writes (engine/world_file.hpp, Simulation::SaveState).
//
//   crowdrecon_bench_device --worlds=DIR [--threads=1,2,16] [Google Benchmark flags]
//
// For every DIR/<name>.world with its DIR/<name>.state: Step/<name>/cpu/threads:N
// for each N, and Step/<name>/cuda/threads:N where CUDA is available; and the
// same as Run/...: one simulated second from the state, timed whole. The
// steps are those of bench_kernels' Step benchmarks (the state is restored
// every 100 steps, timer paused), so the figures compare. Items per second
// are agent-steps per second. Before timing, the CUDA run is compared with
// the processor's over 200 steps: the benchmark fails if one value differs.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "step_benchmark.hpp"

namespace crowdrecon::bench {

namespace {

constexpr int kCheckSteps = 200;

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct SavedWorld {
  std::string name;
  engine::WorldDef def;
  std::string state;
};

engine::Simulation Make(const SavedWorld& w, int threads, engine::ComputeDevice device) {
  engine::WorldDef def = w.def;
  def.threads = threads;
  def.device = device;
  engine::Simulation sim(std::move(def));
  sim.LoadState(w.state);
  return sim;
}

bool Same(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// The CUDA run against the processor's, every value of every body and contact.
void CheckSameResults(const SavedWorld& w) {
  engine::Simulation cpu = Make(w, 1, engine::ComputeDevice::kCpu);
  engine::Simulation gpu = Make(w, 1, engine::ComputeDevice::kCuda);
  for (int step = 0; step < kCheckSteps; ++step) {
    cpu.Step();
    gpu.Step();
  }
  const auto& a = cpu.bodies();
  const auto& b = gpu.bodies();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!Same(a.position_m[i].x, b.position_m[i].x) || !Same(a.position_m[i].y, b.position_m[i].y) ||
        !Same(a.angle_rad[i], b.angle_rad[i]) || !Same(a.contact_force_n[i].x, b.contact_force_n[i].x))
      throw std::runtime_error(w.name + ": CUDA and processor differ at person " + std::to_string(i + 1));
  const auto& ca = cpu.contacts();
  const auto& cb = gpu.contacts();
  if (ca.size() != cb.size()) throw std::runtime_error(w.name + ": CUDA and processor differ in contact count");
  for (std::size_t k = 0; k < ca.size(); ++k)
    if (ca[k].a != cb[k].a || ca[k].b != cb[k].b || ca[k].feature != cb[k].feature ||
        !Same(ca[k].normal_force_n, cb[k].normal_force_n) || !Same(ca[k].tangential_force_n, cb[k].tangential_force_n) ||
        !Same(ca[k].tangential_spring_m, cb[k].tangential_spring_m))
      throw std::runtime_error(w.name + ": CUDA and processor differ at contact " + std::to_string(k));
  std::printf("%s: CUDA and processor identical after %d steps (%zu people, %zu contacts)\n", w.name.c_str(),
              kCheckSteps, a.size(), ca.size());
}

void Step(benchmark::State& state, const SavedWorld& w, int threads, engine::ComputeDevice device) {
  engine::Simulation sim = Make(w, threads, device);
  TimeSteps(state, sim, w.state);
}

// A whole second of simulated time from the saved state, neighbour-list
// rebuilds and all (one iteration per repetition): agent-steps per second and
// the real-time factor of the engine alone (no run file is written).
void Run(benchmark::State& state, const SavedWorld& w, int threads, engine::ComputeDevice device) {
  constexpr double kSeconds = 1.0;
  std::int64_t agent_steps = 0;
  double simulated = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    engine::Simulation sim = Make(w, threads, device);
    const double start = sim.time_s();
    const std::uint64_t steps = sim.step_count();
    state.ResumeTiming();
    sim.AdvanceTo(start + kSeconds);
    agent_steps += static_cast<std::int64_t>((sim.step_count() - steps) * sim.bodies().size());
    simulated += sim.time_s() - start;
  }
  state.SetItemsProcessed(agent_steps);
  state.counters["simulated_s"] = simulated;
  state.counters["real_time_factor"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}

std::vector<int> ParseThreads(const std::string& list) {
  std::vector<int> threads;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    const int t = std::atoi(item.c_str());
    if (t < 1) throw std::runtime_error("--threads: \"" + item + "\" is not a positive thread count");
    threads.push_back(t);
  }
  return threads;
}

}  // namespace

}  // namespace crowdrecon::bench

int main(int argc, char** argv) {
  using namespace crowdrecon;
  std::string worlds_dir, threads_list = "1,2";
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--worlds=", 0) == 0)
      worlds_dir = arg.substr(9);
    else if (arg.rfind("--threads=", 0) == 0)
      threads_list = arg.substr(10);
    else
      rest.push_back(argv[i]);
  }
  int rest_count = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_count, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rest_count, rest.data())) return 1;
  try {
    if (worlds_dir.empty()) throw std::runtime_error("--worlds=DIR is required (see the comment at the top)");
    std::vector<bench::SavedWorld> worlds;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(worlds_dir))
      if (entry.path().extension() == ".world") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) throw std::runtime_error(worlds_dir + ": no .world files");
    for (const auto& file : files) {
      std::filesystem::path state_file = file;
      state_file.replace_extension(".state");
      worlds.push_back({file.stem().string(), engine::LoadWorldFile(file), bench::ReadFile(state_file)});
    }
    std::string why;
    const bool cuda = engine::CudaAvailable(&why);
    if (!cuda) std::printf("CUDA benchmarks left out: %s\n", why.c_str());
    if (cuda)
      for (const auto& w : worlds) bench::CheckSameResults(w);
    const std::vector<int> threads = bench::ParseThreads(threads_list);
    for (const auto& w : worlds)
      for (engine::ComputeDevice device : {engine::ComputeDevice::kCpu, engine::ComputeDevice::kCuda}) {
        if (device == engine::ComputeDevice::kCuda && !cuda) continue;
        for (int t : threads) {
          const std::string suffix = w.name + "/" + engine::ToString(device) + "/threads:" + std::to_string(t);
          benchmark::RegisterBenchmark(("Step/" + suffix).c_str(),
                                       [&w, t, device](benchmark::State& s) { bench::Step(s, w, t, device); })
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
          benchmark::RegisterBenchmark(("Run/" + suffix).c_str(),
                                       [&w, t, device](benchmark::State& s) { bench::Run(s, w, t, device); })
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime()
              ->Iterations(1);
        }
      }
    benchmark::RunSpecifiedBenchmarks();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon_bench_device: %s\n", e.what());
    return 1;
  }
  benchmark::Shutdown();
  return 0;
}
