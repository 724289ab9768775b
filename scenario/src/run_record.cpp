#include "crowdrecon/scenario/run_record.hpp"

#include <algorithm>
#include <vector>

#include "crowdrecon/reports/chest_load.hpp"

namespace crowdrecon::scenario {

static_assert(static_cast<int>(engine::PersonState::kWalking) == static_cast<int>(runfile::PersonStatus::kWalking) &&
                  static_cast<int>(engine::PersonState::kFallen) == static_cast<int>(runfile::PersonStatus::kFallen) &&
                  static_cast<int>(engine::PersonState::kRemoved) == static_cast<int>(runfile::PersonStatus::kRemoved),
              "the run file's person_state.state codes are the engine's PersonState values");

runfile::RunSetup RunSetupOf(const engine::Simulation& sim, const std::vector<std::string>& target_names) {
  runfile::RunSetup setup;
  const engine::WorldDef& def = sim.definition();
  for (const engine::BodyShape& s : def.shapes) setup.shapes.push_back({s.radius_m, s.vertices});
  const engine::BodyState& b = sim.bodies();
  setup.people.reserve(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    const std::uint32_t t = b.target[i];
    setup.people.push_back({b.shape[i], b.mass_kg[i], b.inertia_kg_m2[i], b.desired_speed_m_per_s[i], b.group[i],
                            t < target_names.size() ? target_names[t] : std::to_string(t)});
  }
  for (const engine::Wall& w : def.walls) setup.walls.push_back({w.closed, w.radius_m, w.points});
  return setup;
}

runfile::RunFileWriter CreateRunFile(const std::filesystem::path& file, runfile::RunHeader header,
                                     const engine::Simulation& sim, const std::vector<std::string>& target_names) {
  return CreateRunFileOf(file, std::move(header), sim, RunSetupOf(sim, target_names));
}

runfile::RunFileWriter CreateRunFileOf(const std::filesystem::path& file, runfile::RunHeader header,
                                       const engine::Simulation& sim, const runfile::RunSetup& setup) {
  header.periodic_box = sim.definition().periodic;
  return runfile::RunFileWriter::Create(file, header, setup);
}

void PersonLoads(const engine::Simulation& sim, std::vector<double>* load) {
  load->assign(sim.bodies().size(), 0.0);
  for (const engine::Contact& c : sim.contacts()) {
    const double force = Length(c.Force());
    (*load)[c.a] += force;
    if (!c.wall) (*load)[c.b] += force;
  }
}

void ChestLoadsOf(const engine::Simulation& sim, std::vector<double>* chest, std::vector<double>* lateral) {
  const engine::BodyState& b = sim.bodies();
  std::vector<reports::Pose> poses(b.size());
  for (std::size_t i = 0; i < b.size(); ++i)
    poses[i] = {b.position_m[i], b.angle_rad[i], b.state[i] != engine::PersonState::kRemoved};
  std::vector<reports::LoadContact> contacts;
  contacts.reserve(sim.contacts().size());
  for (const engine::Contact& c : sim.contacts()) contacts.push_back({c.a, c.b, c.wall, c.point_m, c.Force()});
  const std::vector<reports::ChestLoad> loads = reports::ChestLoads(poses, contacts, sim.definition().periodic);
  chest->resize(b.size());
  lateral->resize(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    (*chest)[i] = loads[i].chest_n;
    (*lateral)[i] = loads[i].lateral_n;
  }
}

void PersonChestLoads(const engine::Simulation& sim, std::vector<double>* load) {
  std::vector<double> lateral;
  ChestLoadsOf(sim, load, &lateral);
  for (std::size_t i = 0; i < load->size(); ++i) (*load)[i] = std::max((*load)[i], lateral[i]);
}

void TakeSnapshot(const engine::Simulation& sim, std::int64_t frame, const std::vector<runfile::Event>& events,
                  bool with_contacts, runfile::FrameSnapshot* out) {
  runfile::FrameSnapshot& f = *out;
  const engine::BodyState& b = sim.bodies();
  f.frame = frame;
  f.time_s = sim.time_s();
  f.person.clear();
  f.position_m.clear();
  f.velocity_m_per_s.clear();
  f.angle_rad.clear();
  f.angular_velocity_rad_per_s.clear();
  f.state.clear();
  std::vector<double>& load = f.load_n;
  PersonLoads(sim, &load);
  ChestLoadsOf(sim, &f.chest_load_n, &f.lateral_load_n);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.state[i] == engine::PersonState::kRemoved) continue;
    f.person.push_back(b.id[i]);  // who is in this slot (a timeline's slots change hands)
    f.position_m.push_back(b.position_m[i]);
    f.velocity_m_per_s.push_back(b.velocity_m_per_s[i]);
    f.angle_rad.push_back(b.angle_rad[i]);
    f.angular_velocity_rad_per_s.push_back(b.angular_velocity_rad_per_s[i]);
    f.state.push_back(static_cast<runfile::PersonStatus>(b.state[i]));
    f.chest_load_n[kept] = f.chest_load_n[i];
    f.lateral_load_n[kept] = f.lateral_load_n[i];
    load[kept++] = load[i];  // kept <= i: compacts in place
  }
  load.resize(kept);
  f.chest_load_n.resize(kept);
  f.lateral_load_n.resize(kept);
  f.with_contacts = with_contacts;
  f.contacts.clear();  // (every frame: their brief is written either way)
  f.contacts.reserve(sim.contacts().size());
  for (const engine::Contact& c : sim.contacts())
    f.contacts.push_back({b.id[c.a], c.wall ? c.b : b.id[c.b], c.wall, c.point_m, c.normal, c.overlap_m,
                          c.normal_force_n, c.tangential_force_n});
  f.events = events;
  f.with_census = false;
}

void WriteFrame(runfile::RunFileWriter& writer, const engine::Simulation& sim, std::int64_t frame,
                const std::vector<runfile::Event>& events, bool with_contacts) {
  runfile::FrameSnapshot snapshot;
  TakeSnapshot(sim, frame, events, with_contacts, &snapshot);
  writer.WriteFrame(snapshot);
}

}  // namespace crowdrecon::scenario
