// crowdrecon_bench_lammps: the crowdrecon side of the comparison with LAMMPS
// (bench/README.md, "LAMMPS comparison").
//
//   crowdrecon_bench_lammps --out DIR [--scenario lammps-2000] [--steps 1000] [--threads 1,2]
//
// 1. builds the packing of a benchmark scenario through the scenario library;
// 2. writes it for LAMMPS: DIR/packing.data (atom_style body rounded/polygon)
//    and DIR/in.packing (pair_style body/rounded/polygon with crowdrecon's
//    stiffness, the equivalent damping coefficients and crowdrecon's time step),
//    and the parameter mapping to DIR/mapping.json;
// 3. times crowdrecon's own Step() on the same packing for the same number of
//    steps with each thread count, printing one line per run:
//      RESULT {"code": "crowdrecon", "threads": 2, "steps": ..., "people": ...,
//              "seconds": ..., "agent_steps_per_s": ..., ...}
// bench/lammps_compare.py runs this, then LAMMPS, and reports the ratio.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_worlds.hpp"
#include "stage_profile.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::bench {

namespace {

constexpr double kPi = std::numbers::pi;

std::string Num(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// Restitution factor of eq. (19) inverted: gamma = factor * sqrt(k / m).
double RestitutionFactor(double restitution) {
  const double l = -std::log(restitution);
  return 2.0 * l / std::sqrt(kPi * kPi + l * l);
}

// What LAMMPS is given, and where each value comes from (also bench/README.md).
struct LammpsMapping {
  double dt_s = 0.0;               // crowdrecon's time step for this world
  double kn_n_per_m = 0.0;         // k_n: the same linear spring per vertex contact
  double mean_pair_mass_kg = 0.0;  // mean m_ab = m_a m_b / (m_a + m_b) over touching pairs (eq. 14)
  double c_n_n_s_per_m = 0.0;      // m_ab gamma_n of a single-point contact (eqs. 11, 19)
  double c_t_n_s_per_m = 0.0;      // m_ab gamma_t, likewise (eq. 12)
  double skin_m = 0.0;             // LAMMPS neighbour skin (see WriteLammpsInput)
  double relaxation_time_s = 0.0;  // tau of the self-driven force (eq. 3)
  int vertices_min = 0, vertices_max = 0;
  std::size_t people = 0;
  std::size_t counter_flow = 0;
};

LammpsMapping MapParameters(const engine::Simulation& sim) {
  const engine::WorldDef& def = sim.definition();
  const engine::ModelParameters& mp = def.parameters;
  const engine::BodyState& b = sim.bodies();
  LammpsMapping m;
  m.dt_s = sim.time_step_s();
  m.kn_n_per_m = mp.normal_stiffness_n_per_m;
  m.relaxation_time_s = mp.relaxation_time_s;
  m.people = b.size();
  // LAMMPS has one damping coefficient (N s/m) for every pair; crowdrecon
  // derives gamma per pair from the restitution and the pair's reduced mass.
  // Use the mean reduced mass of the pairs touching in the packing (all
  // people's mean mass halved if none touch).
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (const engine::Contact& c : sim.contacts())
    if (!c.wall) pairs.insert({c.a, c.b});
  double sum = 0.0;
  for (const auto& [i, j] : pairs) sum += b.mass_kg[i] * b.mass_kg[j] / (b.mass_kg[i] + b.mass_kg[j]);
  if (!pairs.empty()) {
    m.mean_pair_mass_kg = sum / double(pairs.size());
  } else {
    double total = 0.0;
    for (double mass : b.mass_kg) total += mass;
    m.mean_pair_mass_kg = total / double(b.size()) / 2.0;
  }
  const double factor = RestitutionFactor(mp.restitution);
  m.c_n_n_s_per_m = factor * std::sqrt(mp.normal_stiffness_n_per_m * m.mean_pair_mass_kg);
  switch (mp.tangential_damping) {
    case engine::TangentialDamping::kFromRestitution:
      m.c_t_n_s_per_m = factor * std::sqrt(mp.tangential_stiffness_n_per_m * m.mean_pair_mass_kg);
      break;
    case engine::TangentialDamping::kEqualToNormal: m.c_t_n_s_per_m = m.c_n_n_s_per_m; break;
    case engine::TangentialDamping::kFixed:
      m.c_t_n_s_per_m = m.mean_pair_mass_kg * mp.tangential_damping_rate_per_s;
      break;
  }
  // LAMMPS's pair cut-off is the sum of the enclosing radii of the cores,
  // without the rounded radii; a skin of 2 r_max + 0.1 m makes its neighbour
  // list reach as far as crowdrecon's (bound_a + bound_b + 0.1 m skin).
  double radius_max = 0.0;
  m.vertices_min = 1 << 30;
  for (const engine::BodyShape& s : def.shapes) {
    radius_max = std::max(radius_max, s.radius_m);
    m.vertices_min = std::min(m.vertices_min, static_cast<int>(s.vertices.size()));
    m.vertices_max = std::max(m.vertices_max, static_cast<int>(s.vertices.size()));
  }
  m.skin_m = 2.0 * radius_max + 0.1;
  for (std::uint32_t g : b.group) m.counter_flow += g == 1 ? 1 : 0;
  return m;
}

// Data file for atom_style body rounded/polygon (LAMMPS "Howto body"): per
// atom "id type bodyflag mass x y z"; per body "id 1 M", the vertex count N,
// then M = 6 + 3 N + 1 doubles: the inertia tensor in the box frame (ixx iyy
// izz ixy ixz iyz; only izz matters in 2d), the vertices relative to the
// centre of mass in the box frame (current orientation), and the rounded
// diameter (twice the sphero-radius).
void WriteLammpsData(const engine::Simulation& sim, const std::string& title, const std::filesystem::path& file) {
  const engine::WorldDef& def = sim.definition();
  const engine::BodyState& b = sim.bodies();
  if (!def.periodic.x || !def.periodic.y)
    throw InputError(title + ": the LAMMPS comparison needs a box periodic along x and y");
  std::ofstream out(file);
  if (!out) throw InputError(file.string() + ": cannot write");
  const std::size_t n = b.size();
  out << "LAMMPS data file: " << title << ", written by crowdrecon_bench_lammps\n\n";
  out << n << " atoms\n" << n << " bodies\n2 atom types\n\n";
  out << Num(def.periodic.min_m.x) << " " << Num(def.periodic.max_m.x) << " xlo xhi\n";
  out << Num(def.periodic.min_m.y) << " " << Num(def.periodic.max_m.y) << " ylo yhi\n";
  out << "-0.5 0.5 zlo zhi\n\nAtoms # body\n\n";
  // Type 1: the main flow (group 0), type 2: the counter-flow (group 1).
  for (std::size_t i = 0; i < n; ++i)
    out << i + 1 << " " << b.group[i] + 1 << " 1 " << Num(b.mass_kg[i]) << " " << Num(b.position_m[i].x) << " "
        << Num(b.position_m[i].y) << " 0\n";
  out << "\nBodies\n\n";
  for (std::size_t i = 0; i < n; ++i) {
    const engine::BodyShape& s = def.shapes[b.shape[i]];
    const std::size_t nv = s.vertices.size();
    out << i + 1 << " 1 " << 6 + 3 * nv + 1 << "\n" << nv << "\n";
    // A lamina: ixx + iyy = izz; their split does not matter in 2d.
    const double izz = b.inertia_kg_m2[i];
    out << Num(izz / 2) << " " << Num(izz / 2) << " " << Num(izz) << " 0 0 0\n";
    const double c = std::cos(b.angle_rad[i]), sn = std::sin(b.angle_rad[i]);
    for (const Vec2& v : s.vertices) out << Num(c * v.x - sn * v.y) << " " << Num(sn * v.x + c * v.y) << " 0\n";
    out << Num(2.0 * s.radius_m) << "\n";
  }
  // Per-person desired speed v0 for the self-driven force (fix property/atom d_v0).
  out << "\nDesiredSpeeds\n\n";
  for (std::size_t i = 0; i < n; ++i) out << i + 1 << " " << Num(b.desired_speed_m_per_s[i]) << "\n";
  if (!out) throw InputError(file.string() + ": write failed");
}

void WriteLammpsInput(const LammpsMapping& m, const std::string& title, std::size_t steps,
                      const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw InputError(file.string() + ": cannot write");
  out << "# LAMMPS input written by crowdrecon_bench_lammps: " << title << "\n"
      << "# The packing, stiffness, damping and time step of crowdrecon's run; the mapping\n"
      << "# of every value is in mapping.json and bench/README.md. Run from this folder:\n"
      << "#   mpirun -np 2 lmp -in in.packing [-var steps N]\n\n"
      << "variable steps index " << steps << "\n"
      << "variable thermo_every equal ceil(v_steps/10)\n\n"
      << "units si\ndimension 2\nboundary p p p\n"
      << "atom_style body rounded/polygon " << m.vertices_min << " " << m.vertices_max << "\n"
      << "atom_modify map array\n"
      << "fix v0 all property/atom d_v0\n"
      << "read_data packing.data fix v0 NULL DesiredSpeeds\n\n"
      << "# c_n c_t mu delta_ua cutoff: mu = 0 (in this pair style mu scales the normal\n"
      << "# force, it is not Coulomb friction); delta_ua = 1 m keeps the contact-length\n"
      << "# factor j_a = 1 (bodies are < 0.5 m); cutoff 0 = contact only (no cohesion).\n"
      << "pair_style body/rounded/polygon " << Num(m.c_n_n_s_per_m) << " " << Num(m.c_t_n_s_per_m) << " 0.0 1.0 0.0\n"
      << "# k_n (N/m) and k_na = 0 (no cohesion)\n"
      << "pair_coeff * * " << Num(m.kn_n_per_m) << " 0.0\n"
      << "comm_modify vel yes\n"
      << "neighbor " << Num(m.skin_m) << " bin\n"
      << "neigh_modify every 1 delay 0 check yes\n"
      << "timestep " << Num(m.dt_s) << "\n\n"
      << "# Self-driven force of eq. (3), m (v0 e - v) / tau, with e = +x for type 1 (main\n"
      << "# flow) and -x for type 2 (counter-flow): keeps the crowd pressed together.\n"
      << "variable tau equal " << Num(m.relaxation_time_s) << "\n"
      << "compute v0 all property/atom d_v0\n"
      << "variable fx atom mass*(c_v0*(3-2*type)-vx)/v_tau\n"
      << "variable fy atom -mass*vy/v_tau\n"
      << "fix drive all addforce v_fx v_fy 0.0\n"
      << "fix move all nve/body\n"
      << "fix plane all enforce2d\n\n"
      << "thermo_style custom step ke pe\n"
      << "thermo_modify norm no\n"
      << "thermo ${thermo_every}\n"
      << "run ${steps}\n";
  if (!out) throw InputError(file.string() + ": write failed");
}

void WriteMapping(const LammpsMapping& m, const std::string& scenario, const std::filesystem::path& file) {
  std::ofstream out(file);
  out << "{\n  \"scenario\": \"" << scenario << "\",\n"
      << "  \"people\": " << m.people << ",\n  \"counter_flow\": " << m.counter_flow << ",\n"
      << "  \"vertices\": [" << m.vertices_min << ", " << m.vertices_max << "],\n"
      << "  \"time_step_s\": " << Num(m.dt_s) << ",\n"
      << "  \"k_n_n_per_m\": " << Num(m.kn_n_per_m) << ",\n"
      << "  \"mean_pair_mass_kg\": " << Num(m.mean_pair_mass_kg) << ",\n"
      << "  \"c_n_n_s_per_m\": " << Num(m.c_n_n_s_per_m) << ",\n"
      << "  \"c_t_n_s_per_m\": " << Num(m.c_t_n_s_per_m) << ",\n"
      << "  \"mu\": 0,\n  \"delta_ua_m\": 1,\n  \"cutoff_m\": 0,\n"
      << "  \"skin_m\": " << Num(m.skin_m) << ",\n"
      << "  \"relaxation_time_s\": " << Num(m.relaxation_time_s) << "\n}\n";
}

struct Args {
  std::string scenario = "lammps-2000";
  std::string out;
  std::size_t steps = 1000;
  std::vector<int> threads = {1, 2};
  bool write_only = false;
  bool profile = false;
};

int Run(const Args& args) {
  const std::filesystem::path scenario_file = ScenarioPath(args.scenario);
  const scenario::BuiltWorld& built = CachedWorld(args.scenario);
  std::filesystem::create_directories(args.out);
  const std::string title = scenario_file.filename().string() + " (" +
                            std::to_string(built.world.people.size()) + " people)";
  {
    const engine::Simulation sim(built.world);
    const LammpsMapping m = MapParameters(sim);
    WriteLammpsData(sim, title, std::filesystem::path(args.out) / "packing.data");
    WriteLammpsInput(m, title, args.steps, std::filesystem::path(args.out) / "in.packing");
    WriteMapping(m, scenario_file.string(), std::filesystem::path(args.out) / "mapping.json");
    std::printf("MAPPING {\"time_step_s\": %.17g, \"k_n_n_per_m\": %.17g, \"c_n_n_s_per_m\": %.17g, "
                "\"c_t_n_s_per_m\": %.17g, \"mean_pair_mass_kg\": %.17g, \"skin_m\": %.17g, \"people\": %zu}\n",
                m.dt_s, m.kn_n_per_m, m.c_n_n_s_per_m, m.c_t_n_s_per_m, m.mean_pair_mass_kg, m.skin_m, m.people);
    std::fflush(stdout);
  }
  if (args.write_only) return 0;
  for (int threads : args.threads) {
    engine::WorldDef def = built.world;
    def.threads = threads;
    engine::Simulation sim(std::move(def));
    const std::size_t contacts_start = sim.contacts().size();
    const double elastic_start = sim.ElasticEnergy();
    const engine::Profile before = sim.profile();
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < args.steps; ++k) sim.Step();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double people = static_cast<double>(sim.bodies().size());
    if (args.profile)  // the construction's first force evaluation left out
      std::printf("PROFILE threads %d, %s\n", threads, StageProfileText(before, sim.profile(), args.steps).c_str());
    std::printf("RESULT {\"code\": \"crowdrecon\", \"threads\": %d, \"steps\": %zu, \"people\": %zu, "
                "\"seconds\": %.6g, \"agent_steps_per_s\": %.6g, \"contacts_start\": %zu, \"contacts_end\": %zu, "
                "\"neighbour_pairs\": %zu, \"elastic_energy_start_j\": %.6g, \"elastic_energy_end_j\": %.6g, "
                "\"kinetic_energy_end_j\": %.6g}\n",
                threads, args.steps, sim.bodies().size(), seconds, people * double(args.steps) / seconds,
                contacts_start, sim.contacts().size(), sim.neighbour_pair_count(), elastic_start,
                sim.ElasticEnergy(), sim.KineticEnergy());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

}  // namespace crowdrecon::bench

int main(int argc, char** argv) {
  crowdrecon::bench::Args args;
  CLI::App app{"Writes a benchmark packing for LAMMPS and times crowdrecon on it (bench/README.md)"};
  app.add_option("--scenario", args.scenario, "Scenario name under bench/scenarios/, or a scenario file")
      ->capture_default_str();
  app.add_option("-o,--out", args.out, "Folder for packing.data, in.packing and mapping.json")->required();
  app.add_option("--steps", args.steps, "Steps to time (and the default of the LAMMPS input)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", args.threads, "Thread counts to time crowdrecon with")
      ->delimiter(',')
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_flag("--write-only", args.write_only, "Only write the LAMMPS files");
  app.add_flag("--profile", args.profile, "Also print milliseconds per step of each stage of crowdrecon's step");
  CLI11_PARSE(app, argc, argv);
  try {
    return crowdrecon::bench::Run(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon_bench_lammps: %s\n", e.what());
    return 1;
  }
}
