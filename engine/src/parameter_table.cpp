#include "crowdrecon/engine/parameter_table.hpp"

#include <array>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::engine {

namespace {

using P = ModelParameters;
using Kind = ParameterInfo::Kind;

constexpr const char* kTangentialDampingChoices[] = {"from_restitution", "equal_to_normal", "fixed"};
constexpr const char* kFacingChoices[] = {"velocity", "desired_direction"};
constexpr const char* kIntegratorChoices[] = {"velocity_verlet", "gear5"};
constexpr const char* kTimeStepModeChoices[] = {"fixed", "adaptive"};
constexpr const char* kBackForceTriggerChoices[] = {"velocity", "averaged_velocity"};
constexpr const char* kTangentialSpringChoices[] = {"history", "none", "creeping"};
constexpr const char* kGaitJitterChoices[] = {"none", "isotropic"};
// Yielding and ShoulderTurn: what a person does when blocked.
constexpr const char* kWhenBlockedChoices[] = {"none", "when_blocked"};
constexpr const char* kGiveWayChoices[] = {"none", "where_room"};
constexpr const char* kSlopeResponseChoices[] = {"body_force", "held"};
constexpr const char* kDriveReactionChoices[] = {"instant", "lagged"};
constexpr const char* kHeadwayChoices[] = {"none", "time_gap"};
constexpr const char* kSocialForceChoices[] = {"none", "circular"};
constexpr const char* kCentrifugalChoices[] = {"none", "generalized"};
constexpr const char* kAnticipationChoices[] = {"none", "time_to_collision"};
constexpr const char* kSidePreferenceGateChoices[] = {"always", "slowed"};

ParameterInfo Number(const char* name, double P::*field, const char* unit, double min, double max, const char* source,
                     const char* meaning, const char* default_from = nullptr) {
  ParameterInfo info;
  info.kind = Kind::kNumber;
  info.name = name;
  info.number = field;
  info.unit = unit;
  info.min = min;
  info.max = max;
  info.source = source;
  info.meaning = meaning;
  info.default_from = default_from;
  return info;
}

ParameterInfo Flag(const char* name, bool P::*field, const char* source, const char* meaning) {
  ParameterInfo info;
  info.kind = Kind::kFlag;
  info.name = name;
  info.flag = field;
  info.source = source;
  info.meaning = meaning;
  return info;
}

// `info`, acting only when `when` ("give_way = where_room") holds.
ParameterInfo When(ParameterInfo info, const char* when, bool (*applies)(const P&)) {
  info.applies_when = when;
  info.applies = applies;
  return info;
}

// An enumeration whose values are 0..N-1, named `choices`.
template <auto Field, std::size_t N>
ParameterInfo Choice(const char* name, const char* const (&choices)[N], const char* source, const char* meaning) {
  ParameterInfo info;
  info.kind = Kind::kChoice;
  info.name = name;
  info.choices = choices;
  info.choice_count = N;
  info.source = source;
  info.meaning = meaning;
  info.get_choice = [](const P& p) { return static_cast<int>(p.*Field); };
  info.set_choice = [](P& p, int value) { p.*Field = static_cast<std::remove_reference_t<decltype(p.*Field)>>(value); };
  return info;
}

auto MakeTable() {
  return std::array{
      // --- Contact forces (eqs. 7-14, 19) ---
      Number("normal_stiffness_n_per_m", &P::normal_stiffness_n_per_m, "N/m", 1.0, 1e9, "Table 1",
             "k_n, normal stiffness of contacts (thorax deformation data)"),
      Number("tangential_stiffness_n_per_m", &P::tangential_stiffness_n_per_m, "N/m", 1.0, 1e9, "Table 1; ERRATA 3",
             "k_t, tangential stiffness of contacts (the text's \"k_6\")"),
      Number("friction_coefficient", &P::friction_coefficient, "", 0.0, 5.0, "Table 1",
             "mu, Coulomb friction of contacts (cloth on cloth)"),
      Number("restitution", &P::restitution, "", 0.01, 1.0, "Table 1; ERRATA 1",
             "epsilon, restitution of person-person contacts; gamma_n follows per contact (ERRATA 2)"),
      Number("wall_restitution", &P::wall_restitution, "", 0.01, 1.0, "Table 1; ERRATA 1",
             "epsilon of person-wall contacts (a scenario without it uses restitution)", "restitution"),
      Choice<&P::tangential_damping>("tangential_damping", kTangentialDampingChoices, "ERRATA 2",
             "how gamma_t is set: from the restitution with k_t, equal to gamma_n, or fixed"),
      When(Number("tangential_damping_rate_per_s", &P::tangential_damping_rate_per_s, "1/s", 0.0, 1e6, "ERRATA 2",
             "gamma_t when tangential_damping is fixed"),
           "tangential_damping = fixed", [](const P& p) { return p.tangential_damping == TangentialDamping::kFixed; }),
      Choice<&P::tangential_spring>("tangential_spring", kTangentialSpringChoices, "eqs. 9-10; issue 19",
             "history: the tangential spring accumulates while a contact lasts (static friction); none: only "
             "the tangential dashpot of eq. 12; creeping: as history, relaxing over "
             "tangential_spring_relaxation_time_s (issue 39)"),
      Flag("allow_tensile_normal_force", &P::allow_tensile_normal_force, "eq. 19",
           "let the dashpot pull at the end of a contact (false: normal force clamped at zero)"),
      // --- Ground reaction forces (eqs. 3, 15) ---
      Flag("ground_reaction", &P::ground_reaction, "eqs. 3, 15-17",
           "people walk (self-driven force, back force, torques); false: passive rigid bodies"),
      Number("relaxation_time_s", &P::relaxation_time_s, "s", 0.01, 100.0, "text",
             "tau, relaxation time of the self-driven force (eq. 3)"),
      Number("back_force_gamma", &P::back_force_gamma, "", 0.0, 100.0, "Table 1 (fitted to footage)",
             "Gamma, back force of people pushed from behind (eq. 15)"),
      Choice<&P::back_force_trigger>("back_force_trigger", kBackForceTriggerChoices, "eq. 15; issue 19",
             "what Theta of eq. 15 reads: the instantaneous velocity along e (the paper), or that velocity "
             "averaged over back_force_reaction_time_s"),
      When(Number("back_force_reaction_time_s", &P::back_force_reaction_time_s, "s", 0.01, 10.0, "issue 19",
             "time constant of the averaged velocity of back_force_trigger = averaged_velocity (about one step)"),
           "back_force_trigger = averaged_velocity", [](const P& p) { return p.back_force_trigger == BackForceTrigger::kAveragedVelocity; }),
      // --- Torques (eqs. 16-17) ---
      Number("torsion_stiffness_lambda", &P::torsion_stiffness_lambda, "", 0.0, 1e4, "Table 1 (fitted to footage)",
             "lambda, torsion stiffness of the motive torque (eq. 16; ERRATA 4)"),
      Number("rotation_relaxation_time_s", &P::rotation_relaxation_time_s, "s", 0.01, 100.0, "ERRATA 8",
             "relaxation time of rotation in eq. 17 (a scenario without it uses relaxation_time_s)",
             "relaxation_time_s"),
      Choice<&P::facing_target>("facing_target", kFacingChoices, "ERRATA 5",
             "theta_D of eq. 16: the walking velocity's angle, or the desired direction's"),
      // --- Floor ---
      Number("gravity_m_per_s2", &P::gravity_m_per_s2, "m/s^2", 0.0, 100.0, "physics",
             "g, for the body force of a sloping floor"),
      Choice<&P::slope_response>("slope_response", kSlopeResponseChoices,
             "issue 43; Tobler 1993 (hiking function, from Imhof's walking data)",
             "body_force: m g sin(theta) downhill on walking people, held by eq. 3 alone (a person wanting to stand "
             "drifts at tau g sin(theta)); held: the legs hold it, and the desired speed is scaled by Tobler's "
             "exp(-3.5 abs(s + 0.05)) / exp(-3.5 x 0.05) of the grade s along the desired direction"),
      // --- Time integration ---
      Choice<&P::integrator>("integrator", kIntegratorChoices, "ERRATA 12",
             "velocity Verlet (default) or Gear's fifth-order predictor-corrector (the paper's code)"),
      Number("time_step_s", &P::time_step_s, "s", 0.0, 0.1, "ERRATA 12",
             "time step; 0: chosen by the engine from every stiffness and the lightest body"),
      When(Number("time_step_safety", &P::time_step_safety, "", 1e-4, 1.0, "ERRATA 12",
             "the engine's step as a fraction of the integrator's stability limit"),
           "time_step_s = 0", [](const P& p) { return p.time_step_s == 0.0; }),
      Choice<&P::time_step_mode>("time_step_mode", kTimeStepModeChoices, "issue 42",
             "fixed: one step for the whole run; adaptive: the step doubled (up to adaptive_max_safety of the "
             "stability limit) while no pair approaches fast enough for its restitution to suffer (velocity "
             "Verlet only)"),
      When(Number("adaptive_max_safety", &P::adaptive_max_safety, "", 1e-4, 0.5, "issue 42 (docs/decisions.md)",
             "the largest adaptive step as a fraction of the stability limit (a jam's contact network is up "
             "to ~2.5 times stiffer than one pair)"),
           "time_step_mode = adaptive", [](const P& p) { return p.time_step_mode == TimeStepMode::kAdaptive; }),
      When(Number("adaptive_reference_speed_m_per_s", &P::adaptive_reference_speed_m_per_s, "m/s", 0.0, 20.0,
             "issue 42 (docs/decisions.md)",
             "collisions up to this speed keep the fixed step's restitution accuracy, slower ones its absolute "
             "velocity error; 0: the fastest desired speed of the people"),
           "time_step_mode = adaptive", [](const P& p) { return p.time_step_mode == TimeStepMode::kAdaptive; }),
      // --- Extensions beyond the paper (issue 39; off by default) ---
      Choice<&P::gait_jitter>("gait_jitter", kGaitJitterChoices, "issue 39; Wuppertal trajectories",
             "none: eq. 3 as printed; isotropic: eq. 3's desired velocity plus a band-limited random velocity "
             "on both axes (people shifting and stepping in place)"),
      When(Number("gait_jitter_velocity_m_per_s", &P::gait_jitter_velocity_m_per_s, "m/s", 0.0, 5.0,
             "Wuppertal 2018 bottleneck (studies/wuppertal-bottleneck/gait-jitter-from-data.py)",
             "sigma_u, standard deviation per axis of the jitter's velocity"),
           "gait_jitter = isotropic", [](const P& p) { return p.gait_jitter == GaitJitter::kIsotropic; }),
      When(Number("gait_jitter_band_low_hz", &P::gait_jitter_band_low_hz, "Hz", 0.01, 20.0,
             "Wuppertal 2018 bottleneck (studies/wuppertal-bottleneck/gait-jitter-from-data.py)", "lowest frequency of the jitter"),
           "gait_jitter = isotropic", [](const P& p) { return p.gait_jitter == GaitJitter::kIsotropic; }),
      When(Number("gait_jitter_band_high_hz", &P::gait_jitter_band_high_hz, "Hz", 0.01, 20.0,
             "Wuppertal 2018 bottleneck (studies/wuppertal-bottleneck/gait-jitter-from-data.py)",
             "highest frequency of the jitter (at least the lowest)"),
           "gait_jitter = isotropic", [](const P& p) { return p.gait_jitter == GaitJitter::kIsotropic; }),
      When(Number("gait_jitter_seed", &P::gait_jitter_seed, "", 0.0, 4503599627370496.0, "crowdrecon",
             "whole number: the seed of each person's jitter (a scenario without it uses population.seed "
             "modulo 2^52)"),
           "gait_jitter = isotropic", [](const P& p) { return p.gait_jitter == GaitJitter::kIsotropic; }),
      Choice<&P::yielding>("yielding", kWhenBlockedChoices, "issue 39; Wuppertal trajectories",
             "none: eq. 3 as printed; when_blocked: a person pushed back against the desired direction by a "
             "contact with a person drives toward yielding_push_share times the desired speed (walls do not count)"),
      When(Number("yielding_push_share", &P::yielding_push_share, "", 0.0, 1.0,
             "Wuppertal 2018 bottleneck (studies/wuppertal-bottleneck/bottleneck-study.py)",
             "share of the desired speed a blocked person still drives toward (1: the paper's push)"),
           "yielding = when_blocked", [](const P& p) { return p.yielding == Yielding::kWhenBlocked; }),
      When(Number("tangential_spring_relaxation_time_s", &P::tangential_spring_relaxation_time_s, "s", 1e-3, 1e4,
             "issue 39; Wuppertal 2018 bottleneck (studies/wuppertal-bottleneck/bottleneck-study.py)",
             "T of tangential_spring = creeping: a contact held at rest loses its tangential elastic force as exp(-t/T)"),
           "tangential_spring = creeping", [](const P& p) { return p.tangential_spring == TangentialSpring::kCreeping; }),
      Choice<&P::shoulder_turn>("shoulder_turn", kWhenBlockedChoices,
             "issue 39; Yamamoto et al. 2019 (passing in narrow corridors)",
             "none: eq. 16 as printed; when_blocked: a person pushed back against the desired direction by a "
             "person ahead is turned (eq. 16's torque at full gain) toward the desired direction rotated by "
             "shoulder_turn_angle_deg, to the nearer side"),
      When(Number("shoulder_turn_angle_deg", &P::shoulder_turn_angle_deg, "deg", 0.0, 90.0,
             "issue 39; Yamamoto et al. 2019",
             "how far a blocked person turns from the desired direction (90: sideways, a shoulder first)"),
           "shoulder_turn = when_blocked", [](const P& p) { return p.shoulder_turn == ShoulderTurn::kWhenBlocked; }),
      Choice<&P::give_way>("give_way", kGiveWayChoices, "issue 39 (candidate b); issue 19's give-up",
             "none: the paper's model; where_room: a person blocked for give_way_blocked_s who touches at most "
             "give_way_max_contacts people, most heading against them, walks their way for give_way_duration_s"),
      When(Number("give_way_blocked_s", &P::give_way_blocked_s, "s", 0.1, 600.0, "issue 19's give-up",
             "how long a person is blocked (velocity along the desired direction, averaged over 1 s, below "
             "give_way_speed_m_per_s) before giving way"),
           "give_way = where_room", [](const P& p) { return p.give_way == GiveWay::kWhereRoom; }),
      When(Number("give_way_speed_m_per_s", &P::give_way_speed_m_per_s, "m/s", 0.0, 2.0, "issue 19's give-up",
             "below this averaged velocity along the desired direction a person is blocked"),
           "give_way = where_room", [](const P& p) { return p.give_way == GiveWay::kWhereRoom; }),
      When(Number("give_way_duration_s", &P::give_way_duration_s, "s", 0.1, 600.0, "issue 19's give-up",
             "how long a person who gives way walks with the people against them"),
           "give_way = where_room", [](const P& p) { return p.give_way == GiveWay::kWhereRoom; }),
      When(Number("give_way_max_contacts", &P::give_way_max_contacts, "", 0.0, 20.0, "issue 39 (candidate b)",
             "whole number: a person touching more people than this has no room to turn and does not give way"),
           "give_way = where_room", [](const P& p) { return p.give_way == GiveWay::kWhereRoom; }),
      Choice<&P::drive_reaction>("drive_reaction", kDriveReactionChoices,
             "issue 39; Juelich corridors (studies/reaction-time/reaction-time-from-data.py)",
             "instant: eq. 3 as printed, from this step's velocity; lagged: eq. 3 from the velocity perceived "
             "with a first-order lag of drive_reaction_time_s (a reaction time)"),
      When(Number("drive_reaction_time_s", &P::drive_reaction_time_s, "s", 0.01, 10.0,
             "Juelich corridors (studies/reaction-time/reaction-time-from-data.py)",
             "T of drive_reaction = lagged: the time constant (and mean delay) of the perceived velocity"),
           "drive_reaction = lagged", [](const P& p) { return p.drive_reaction == DriveReaction::kLagged; }),
      // --- Keeping a distance (issue 64; off by default; appended: checkpoints read the table's first entries) ---
      Choice<&P::headway>("headway", kHeadwayChoices,
             "issue 64; Tordeux, Chraibi and Seyfried 2016 (the collision-free speed model)",
             "none: eq. 3 as printed; time_gap: the desired direction turned away from near people and the desired "
             "speed capped by the headway to the person ahead, max(0, (s - headway_length_m) / headway_time_gap_s)"),
      When(Number("headway_time_gap_s", &P::headway_time_gap_s, "s", 0.01, 10.0,
                  "Tordeux et al. 2016; JuPedSim's default", "T, the time gap kept to the person ahead"),
           "headway = time_gap", [](const P& p) { return p.headway == Headway::kTimeGap; }),
      When(Number("headway_length_m", &P::headway_length_m, "m", 0.0, 2.0, "Tordeux et al. 2016; JuPedSim's default",
                  "l, the centre distance at which the capped speed is zero, and the width of the lane ahead"),
           "headway = time_gap", [](const P& p) { return p.headway == Headway::kTimeGap; }),
      When(Number("headway_repulsion_strength", &P::headway_repulsion_strength, "", 0.0, 1e3,
                  "Tordeux et al. 2016; JuPedSim's default", "a, how strongly near people turn the desired direction"),
           "headway = time_gap", [](const P& p) { return p.headway == Headway::kTimeGap; }),
      When(Number("headway_repulsion_range_m", &P::headway_repulsion_range_m, "m", 0.001, 2.0,
                  "Tordeux et al. 2016; JuPedSim's default", "D, the range of that turning"),
           "headway = time_gap", [](const P& p) { return p.headway == Headway::kTimeGap; }),
      Choice<&P::social_force>("social_force", kSocialForceChoices,
             "issue 64; Helbing, Farkas and Vicsek 2000; Johansson, Helbing and Shukla 2007",
             "none: the paper's model; circular: every person within reach pushes a walking person away with "
             "social_force_strength_n exp((r_ij - d_ij) / social_force_range_m), weighted by social_force_anisotropy "
             "behind, A once their bounding circles overlap"),
      When(Number("social_force_strength_n", &P::social_force_strength_n, "N", 0.0, 1e5,
                  "Helbing, Farkas and Vicsek 2000", "A, the repulsion at touching bounding circles"),
           "social_force = circular", [](const P& p) { return p.social_force == SocialForce::kCircular; }),
      When(Number("social_force_range_m", &P::social_force_range_m, "m", 0.001, 2.0, "Helbing, Farkas and Vicsek 2000",
                  "B, the range of the repulsion"),
           "social_force = circular", [](const P& p) { return p.social_force == SocialForce::kCircular; }),
      When(Number("social_force_anisotropy", &P::social_force_anisotropy, "", 0.0, 1.0,
                  "Johansson, Helbing and Shukla 2007", "lambda, the weight of people behind (1: isotropic)"),
           "social_force = circular", [](const P& p) { return p.social_force == SocialForce::kCircular; }),
      Choice<&P::centrifugal>("centrifugal", kCentrifugalChoices,
             "issue 64; Chraibi, Seyfried and Schadschneider 2010 (the generalized centrifugal force model)",
             "none: the paper's model; generalized: a walking person is pushed back from each person ahead by "
             "m K (centrifugal_strength v0 + closing speed)^2 / the gap between their speed-dependent ellipses"),
      When(Number("centrifugal_strength", &P::centrifugal_strength, "", 0.0, 10.0, "Chraibi et al. 2010",
                  "eta, the share of the desired speed in the repulsion's numerator"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_cutoff_m", &P::centrifugal_cutoff_m, "m", 0.05, 10.0, "JuPedSim's default",
                  "r_c, the gap beyond which the repulsion is zero"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_interpolation_m", &P::centrifugal_interpolation_m, "m", 0.001, 1.0,
                  "JuPedSim's default", "r_eps, the width of the two interpolations (near contact and near r_c)"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_max_factor", &P::centrifugal_max_factor, "", 1.0, 100.0, "JuPedSim's default",
                  "f_m, the repulsion at touching ellipses in units of its value at the gap r_eps"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_a_min_m", &P::centrifugal_a_min_m, "m", 0.01, 2.0, "Chraibi et al. 2010",
                  "a_min, the ellipse's semi-axis along the velocity at rest"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_a_time_s", &P::centrifugal_a_time_s, "s", 0.0, 5.0, "Chraibi et al. 2010",
                  "tau_a, how the semi-axis along the velocity grows with the speed"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_b_min_m", &P::centrifugal_b_min_m, "m", 0.01, 2.0, "Chraibi et al. 2010",
                  "b_min, the semi-axis across the velocity at the desired speed"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      When(Number("centrifugal_b_max_m", &P::centrifugal_b_max_m, "m", 0.01, 2.0, "Chraibi et al. 2010",
                  "b_max, the semi-axis across the velocity at rest"),
           "centrifugal = generalized", [](const P& p) { return p.centrifugal == Centrifugal::kGeneralized; }),
      Choice<&P::anticipation>("anticipation", kAnticipationChoices,
             "issue 64; Karamouzas, Skinner and Guy 2014 (the time-to-collision power law)",
             "none: the paper's model; time_to_collision: a walking person is pushed off each collision course by "
             "the gradient of the energy anticipation_strength_m2 tau^-2 exp(-tau / anticipation_horizon_s)"),
      When(Number("anticipation_strength_m2", &P::anticipation_strength_m2, "m^2", 0.0, 100.0,
                  "Karamouzas, Skinner and Guy 2014", "k, the energy's scale"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Number("anticipation_horizon_s", &P::anticipation_horizon_s, "s", 0.1, 60.0,
                  "Karamouzas, Skinner and Guy 2014", "tau0, the horizon beyond which collisions are ignored"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Number("anticipation_max_acceleration_m_per_s2", &P::anticipation_max_acceleration_m_per_s2, "m/s^2", 0.01,
                  100.0, "issue 64 (ours: twice eq. 3's largest push at the venues' speeds)",
                  "the ceiling of the anticipation force per unit mass, from each person"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Number("anticipation_radius_m", &P::anticipation_radius_m, "m", 0.1, 20.0,
                  "issue 64 (ours: Karamouzas et al. looked 10 m; half of it for the cost)",
                  "the centre distance within which people anticipate each other"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Number("anticipation_interval_s", &P::anticipation_interval_s, "s", 0.0, 0.5,
                  "issue 66 (multiple time stepping, Tuckerman, Berne and Martyna 1992)",
                  "how often the anticipation force is evaluated: 0 at every step, else once per interval, each "
                  "person keeping its force per unit mass in between"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Number("anticipation_near_m", &P::anticipation_near_m, "m", 0.0, 20.0,
                  "issue 66 (multiple time stepping split by distance)",
                  "with the clock, the centre distance within which the force is evaluated at every step (a smooth "
                  "switch over its last 0.5 m); 0: every pair on the clock"),
           "anticipation_interval_s > 0", [](const P& p) {
             return p.anticipation == Anticipation::kTimeToCollision && p.anticipation_interval_s > 0.0;
           }),
      // --- Sleeping (issue 66; off by default; appended: checkpoints read the table's first entries) ---
      Number("sleep_speed_m_per_s", &P::sleep_speed_m_per_s, "m/s", 0.0, 1.0,
             "issue 66 (Box2D's sleeping, per body; docs/model.md, \"Sleeping\")",
             "0: every walking person is integrated at every step; > 0: a person still (speed and rim speed below "
             "this) for sleep_time_s sleeps (not integrated, drive frozen to hold their mean load while still, "
             "contacts with other sleepers and walls carried) until their load moves from it by more than "
             "sleep_wake_force_n"),
      When(Number("sleep_time_s", &P::sleep_time_s, "s", 0.0, 600.0, "issue 66",
                  "how long a person must be still before sleeping"),
           "sleep_speed_m_per_s > 0", [](const P& p) { return p.sleep_speed_m_per_s > 0.0; }),
      When(Number("sleep_wake_force_n", &P::sleep_wake_force_n, "N", 0.0, 1e4, "issue 66",
                  "how far a sleeper's load (contacts, external force) may move from the mean it held while still "
                  "before it wakes (and that force at the body's farthest core point, as a torque)"),
           "sleep_speed_m_per_s > 0", [](const P& p) { return p.sleep_speed_m_per_s > 0.0; }),
      // --- Side preference (issue 64; off by default; appended: checkpoints read the table's first entries) ---
      When(Number("anticipation_side_preference", &P::anticipation_side_preference, "", -1.0, 1.0,
                  "issue 64 (Moussaid et al. 2009; Xiao et al. 2019: most people avoid to their right)",
                  "the share of the braking part of a walker's anticipation force turned into a step to their right "
                  "(negative: to their left); 0: none"),
           "anticipation = time_to_collision", [](const P& p) { return p.anticipation == Anticipation::kTimeToCollision; }),
      When(Choice<&P::anticipation_side_gate>("anticipation_side_gate", kSidePreferenceGateChoices,
                                               "issue 64 (studies/side-preference/)",
                                               "always: the side step is s times the braking part; slowed: also times "
                                               "max(0, 1 - v.e / v0), only as far as the walker is slowed"),
           "anticipation_side_preference != 0", [](const P& p) {
             return p.anticipation == Anticipation::kTimeToCollision && p.anticipation_side_preference != 0.0;
           }),
  };
}

}  // namespace

std::vector<std::string> SettingsWithoutEffect(const ModelParameters& p, const std::vector<std::string>& given) {
  std::vector<std::string> lines;
  for (const std::string& key : given) {
    const ParameterInfo* info = FindModelParameter(key);
    if (info == nullptr || info->applies == nullptr || info->applies(p)) continue;
    const std::string when = info->applies_when;
    const std::string switch_name = when.substr(0, when.find(" = "));
    std::string here;
    if (const ParameterInfo* sw = FindModelParameter(switch_name)) here = " (here " + switch_name + " is " + sw->ValueText(p) + ")";
    lines.push_back("model." + key + " changes nothing: it acts only when " + when + here);
  }
  return lines;
}

std::span<const ParameterInfo> ModelParameterTable() {
  static const auto table = MakeTable();
  return table;
}

const ParameterInfo* FindModelParameter(const std::string& name) {
  for (const ParameterInfo& info : ModelParameterTable())
    if (name == info.name) return &info;
  return nullptr;
}

std::string ParameterInfo::ValueText(const ModelParameters& p) const {
  switch (kind) {
    case Kind::kNumber: return FormatNumber(p.*number);
    case Kind::kFlag: return p.*flag ? "true" : "false";
    case Kind::kChoice: {
      const int value = get_choice(p);
      return value >= 0 && static_cast<std::size_t>(value) < choice_count ? choices[value] : "?";
    }
  }
  return "?";
}

std::string ParameterInfo::Expected() const {
  switch (kind) {
    case Kind::kNumber: return "in [" + FormatNumber(min) + ", " + FormatNumber(max) + "]";
    case Kind::kFlag: return "true or false";
    case Kind::kChoice: {
      std::string text = "one of ";
      for (std::size_t k = 0; k < choice_count; ++k) text += (k ? ", " : "") + std::string(choices[k]);
      return text;
    }
  }
  return "";
}

std::string ModelParameterTableMarkdown() {
  const ModelParameters defaults;
  std::string text = "| parameter | unit | default | allowed | source | meaning |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const ParameterInfo& info : ModelParameterTable()) {
    std::string value = info.ValueText(defaults);
    if (info.default_from) value += " (or " + std::string(info.default_from) + ")";
    text += "| `" + std::string(info.name) + "` | " + info.unit + " | " + value + " | " + info.Expected() + " | " +
            info.source + " | " + info.meaning + " |\n";
  }
  return text;
}

bool ModelParameters::IsValid(std::string* error) const {
  for (const ParameterInfo& info : ModelParameterTable()) {
    if (info.kind == Kind::kNumber) {
      const double v = this->*info.number;
      if (!(std::isfinite(v) && v >= info.min && v <= info.max)) {
        if (error) *error = std::string(info.name) + " = " + FormatNumber(v) + ", expected " + info.Expected();
        return false;
      }
    } else if (info.kind == Kind::kChoice) {
      const int value = info.get_choice(*this);
      if (value < 0 || static_cast<std::size_t>(value) >= info.choice_count) {
        if (error) *error = std::string(info.name) + " = " + std::to_string(value) + ", expected " + info.Expected();
        return false;
      }
    }
  }
  if (time_step_mode == TimeStepMode::kAdaptive && integrator != Integrator::kVelocityVerlet) {
    if (error) *error = "time_step_mode = adaptive needs integrator = velocity_verlet (Gear's history assumes one step)";
    return false;
  }
  if (sleep_speed_m_per_s > 0.0 && integrator != Integrator::kVelocityVerlet) {
    if (error) *error = "sleep_speed_m_per_s > 0 needs integrator = velocity_verlet (Gear's history assumes every body moves)";
    return false;
  }
  if (gait_jitter_band_high_hz < gait_jitter_band_low_hz) {
    if (error)
      *error = "gait_jitter_band_high_hz = " + FormatNumber(gait_jitter_band_high_hz) +
               ", expected at least gait_jitter_band_low_hz = " + FormatNumber(gait_jitter_band_low_hz);
    return false;
  }
  for (const auto& [name, value] : {std::pair{"gait_jitter_seed", gait_jitter_seed},
                                     std::pair{"give_way_max_contacts", give_way_max_contacts}}) {
    if (value != std::floor(value)) {
      if (error) *error = std::string(name) + " = " + FormatNumber(value) + ", expected a whole number";
      return false;
    }
  }
  return true;
}

}  // namespace crowdrecon::engine
