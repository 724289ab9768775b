// ModelParameters: every physical parameter of the pedestrian model, with the
// paper's value as default (Table 1 and the text of Alonso-Marroquin et al.;
// decisions on its inconsistencies in docs/decisions.md). Names, units,
// ranges, sources and meanings: the parameter table (parameter_table.hpp).
#pragma once

#include <string>

namespace crowdrecon::engine {

// Which angle the motive torque (eq. 16) turns a person toward (ERRATA 5).
enum class FacingTarget {
  kVelocity,          // theta_D = angle of the walking velocity v_i (the paper's definition)
  kDesiredDirection,  // theta_D = angle of the desired direction e_i
};
const char* ToString(FacingTarget t);
bool FromString(const std::string& s, FacingTarget* t);

// How the tangential damping rate gamma_t is set (ERRATA 2: the paper is silent).
enum class TangentialDamping {
  kFromRestitution,  // invert eq. (19) with kt instead of kn: same restitution for tangential oscillation
  kEqualToNormal,    // gamma_t = gamma_n of the same contact
  kFixed,            // gamma_t = tangential_damping_rate_per_s
};
const char* ToString(TangentialDamping t);
bool FromString(const std::string& s, TangentialDamping* t);

// What switches the back force of eq. (15) on (issue 19: the paper's
// Theta(-e.v) reads the instantaneous velocity; a person reacts to being
// pushed back over a reaction time, not within a time step).
enum class BackForceTrigger {
  kVelocity,          // Theta(-e_i . v_i), the instantaneous velocity (the paper's eq. 15)
  kAveragedVelocity,  // Theta(-u_i), u_i the velocity along e_i averaged over back_force_reaction_time_s
};

// Whether contacts keep a tangential spring (eq. 9) from step to step
// (issue 19: the springs hold a plug by static friction).
enum class TangentialSpring {
  kHistory,  // delta_t accumulates while the contact lasts, capped by Coulomb (eqs. 9-10; default)
  kNone,     // no elastic tangential displacement: only the tangential dashpot (eq. 12) acts
  kCreeping, // issue 39: as kHistory, and the displacement relaxes over tangential_spring_relaxation_time_s
};

// Whether people move on their own while they stand or walk in a crowd
// (issue 39; docs/decisions.md, "Issue 39: gait jitter"): people in a dense
// crowd shift their weight and step in place, so their desired velocity is
// not exactly v0 e_i. Measured in the Wuppertal bottleneck's waiting crowd
// (studies/wuppertal-bottleneck/gait-jitter-from-data.py).
enum class GaitJitter {
  kNone,        // the paper's eq. (3): the desired velocity is v0 e_i (default)
  kIsotropic,   // eq. (3) with v0 e_i + u_i(t), u_i band-limited noise on both axes
};

// Whether people who are held up by what is ahead keep pushing with their
// whole self-driven force (issue 39; docs/decisions.md, "Issue 39:
// yielding"): eq. (3) drives everyone toward v0 e_i whatever stands in the
// way, so a blocked crowd leans on its front with the sum of its drives.
enum class Yielding {
  kNone,          // the paper's eq. (3) (default)
  kWhenBlocked,   // a person pushed back against e_i by a contact with a person drives toward push_share v0 e_i
};

// Whether a blocked person turns a shoulder into the way (issue 39;
// docs/decisions.md, "Issue 39: turning the shoulder"): people passing one
// another where there is no room for both breadths turn their bodies
// (Yamamoto et al., Transp. Res. B 122:486, 2019; at a bottleneck the turn
// grows as the width falls toward the shoulders': Sensors 24:1720, 2024).
// Eq. (16) turns a person toward theta_D only in proportion to their speed,
// so a blocked person keeps facing the way they were going.
enum class ShoulderTurn {
  kNone,         // the paper's eq. (16) (default)
  kWhenBlocked,  // a person pushed back against e_i by a person ahead turns toward e_i rotated by the turn angle
};

// Whether a blocked person gives way to the crowd against them where there
// is room to turn (issue 39, candidate (b); docs/decisions.md, "Issue 39:
// giving way where there is room"): issue 19's give-up released plugs and
// then let lanes win for good; conditioned on room to turn, dense plugs stay.
enum class GiveWay {
  kNone,       // the paper's model (default)
  kWhereRoom,  // blocked for give_way_blocked_s, touching at most give_way_max_contacts people, most of them
               // heading against e_i: walk their way for give_way_duration_s
};

// Whether the drive reacts to the person's motion at once or after a
// reaction time (issue 39; docs/decisions.md, "Issue 39: a reaction time"):
// eq. (3) relaxes toward v0 e_i from the velocity of this very step, so a
// person whose way clears pushes off at once and one who is stopped stops
// pushing at once. People react to the person ahead with a delay (measured in
// the Juelich corridors: studies/reaction-time/reaction-time-from-data.py), which
// follow-the-leader models turn into stop-and-go waves.
enum class DriveReaction {
  kInstant,  // the paper's eq. (3): m/tau (v0 e_i - v_i) (default)
  kLagged,   // m/tau (v0 e_i - w_i), w_i the velocity perceived with a first-order lag of drive_reaction_time_s
};

// Keeping a distance from the people ahead (issue 64; off by default): the
// paper's people interact only by touching, so at walking densities they run
// into each other in files (a headway of 0.19 m where the Juelich corridor's
// people keep 0.97 m). The collision-free speed model's two rules (Tordeux,
// Chraibi and Seyfried 2016; JuPedSim's default model), as a behaviour term
// beside the contact forces: the desired direction turned away from near
// people, and the desired speed capped by the headway to the person ahead.
enum class Headway {
  kNone,     // the paper's eq. (3) (default)
  kTimeGap,  // e_i + sum_j a exp((l - d_ij)/D) n_ji normalised; v0_i capped at max(0, (s_i - l)/T)
};

// The social force's repulsion between people (issue 64; off by default):
// the second of the field's forms of keeping a distance, a force beside the
// contact forces (Helbing and Molnar 1995; Helbing, Farkas and Vicsek 2000;
// the circular specification with anisotropy of Johansson, Helbing and
// Shukla 2007).
enum class SocialForce {
  kNone,      // the paper's model (default)
  kCircular,  // A exp((r_ij - d_ij)/B) n_ij (lambda + (1 - lambda)(1 + cos phi_ij)/2) from each person j
};

// The generalized centrifugal force (issue 64; off by default): the third
// form, a repulsion that grows with the speed at which a person closes in on
// another's speed-dependent ellipse (Chraibi, Seyfried and Schadschneider,
// Phys. Rev. E 82:046111, 2010).
// When the anticipation's side preference acts (issue 64): always, or in the
// share a walker is slowed below their desired speed.
enum class SidePreferenceGate {
  kAlways,  // s B (default)
  kSlowed,  // s B max(0, 1 - v.e / v0): a walker at their desired speed does not step aside
};

enum class Centrifugal {
  kNone,         // the paper's model (default)
  kGeneralized,  // -m K_ij (eta v0_i + v_ij)^2 / dist_ij e_ij from each person j ahead, interpolated near 0 and r_c
};

// Anticipation by time to collision (issue 64; off by default): the fourth
// form, the force of the energy E = k tau^-2 exp(-tau/tau0) of the time tau
// to the collision of two bodies moving on (Karamouzas, Skinner and Guy,
// Phys. Rev. Lett. 113:238701, 2014).
enum class Anticipation {
  kNone,             // the paper's model (default)
  kTimeToCollision,  // -m grad_x E(tau) from each person j on a collision course
};

// How a sloping floor acts on walking people (issue 43; docs/itaewon.md).
enum class SlopeResponse {
  kBodyForce,  // issue 19: m g sin(theta) downhill on every walking person (default; eq. 3 alone holds it)
  kHeld,       // the legs hold the slope's pull; the desired speed follows Tobler's hiking function of the grade
};

enum class Integrator {
  kVelocityVerlet,  // second order, symplectic for conservative forces; default
  kGear5,           // fifth-order Gear predictor-corrector, as in the paper's SPOLY code
};
const char* ToString(Integrator t);
bool FromString(const std::string& s, Integrator* t);

// How the step is chosen during a run (issue 42; docs/decisions.md, "An
// adaptive step").
enum class TimeStepMode {
  kFixed,     // one step for the whole run (default; the paper's model as before, bit for bit)
  kAdaptive,  // velocity Verlet only: each step a power-of-two multiple of the fixed step, as long as
              // slow approaches allow (restitution error bounded in absolute terms)
};
const char* ToString(TimeStepMode m);

struct ModelParameters {
  // --- Contact forces (eqs. 7-14, 19; Table 1) -------------------------
  double normal_stiffness_n_per_m = 1e5;      // k_n, Table 1 (thorax deformation data [21])
  double tangential_stiffness_n_per_m = 1e4;  // k_t, Table 1 ("k_6" in the text, ERRATA 3)
  double friction_coefficient = 0.4;          // mu, Table 1 (cloth on cloth)
  // epsilon, Table 1 says 0.4, the text 0.3 (ERRATA 1). We default to Table 1.
  // gamma_n is derived per contact from epsilon and m_ij by inverting eq. (19) (ERRATA 2).
  double restitution = 0.4;
  double wall_restitution = 0.4;  // epsilon for person-wall contacts (same source)
  TangentialDamping tangential_damping = TangentialDamping::kFromRestitution;
  double tangential_damping_rate_per_s = 0.0;  // gamma_t when kFixed (1/s)
  TangentialSpring tangential_spring = TangentialSpring::kHistory;
  // Allow the linear dashpot to pull at the end of a contact (as in eq. 19's
  // derivation); when false the normal force is clamped at zero.
  bool allow_tensile_normal_force = true;

  // --- Ground reaction forces (eqs. 3, 15) -----------------------------
  // false: people are passive rigid bodies (no eqs. 3, 15, 16, 17 and no
  // slope force), as needed by the verification scenes (collisions, momentum).
  bool ground_reaction = true;
  double relaxation_time_s = 2.0 / 3.0;  // tau, text: "tau = 2/3 s"
  // (Desired speeds v0 ~ U(0.8, 1.2) m/s are drawn per person: the
  // scenario's population, scenario::PopulationSpec; PersonDef holds each.)
  double back_force_gamma = 1.2;  // Gamma, Table 1 (fitted to footage)
  BackForceTrigger back_force_trigger = BackForceTrigger::kVelocity;
  // Time constant of u_i for kAveragedVelocity (s): the duration of a step
  // (~0.5 s at a cadence of ~2 steps/s): a person pushed back reacts with
  // the next step, not within milliseconds.
  double back_force_reaction_time_s = 0.5;

  // --- Torques (eqs. 16-17) --------------------------------------------
  double torsion_stiffness_lambda = 27.0;  // lambda, Table 1 (fitted to footage)
  // Relaxation time of rotation in eq. (17); the paper reuses the symbol tau
  // (ERRATA 8), so it defaults to tau.
  double rotation_relaxation_time_s = 2.0 / 3.0;
  FacingTarget facing_target = FacingTarget::kVelocity;

  // --- Extensions beyond the paper (issue 39; off by default) ------------
  // Gait jitter: eq. (3) reads m/tau (v0 e + u - v), u_i(t) a stationary
  // random velocity of standard deviation gait_jitter_velocity_m_per_s per
  // axis whose spectrum is flat between the band's edges (a sum of
  // cosines with random frequencies in the band and random phases, drawn
  // per person from gait_jitter_seed and the person's id: no state, so the
  // same on any thread count and after any resume).
  GaitJitter gait_jitter = GaitJitter::kNone;
  double gait_jitter_velocity_m_per_s = 0.3;  // sigma_u per axis (Wuppertal waiting crowd)
  double gait_jitter_band_low_hz = 0.5;       // where the measured S_u is flat
  double gait_jitter_band_high_hz = 1.5;
  double gait_jitter_seed = 0.0;              // whole number; a scenario's default is its population seed

  // Yielding: a blocked person (pushed back against e_i by someone ahead) drives toward
  // yielding_push_share * v0 e_i instead of v0 e_i (1: the paper's push).
  Yielding yielding = Yielding::kNone;
  double yielding_push_share = 0.0;
  // T of tangential_spring = kCreeping (s): a contact held at rest loses its
  // tangential elastic force as e^(-t/T) (issue 39; docs/decisions.md).
  double tangential_spring_relaxation_time_s = 1.0;
  // Turning the shoulder: a blocked person (as for yielding) is turned by
  // eq. (16)'s torque, at full gain, toward e_i rotated by
  // shoulder_turn_angle_deg to whichever side is nearer their orientation.
  ShoulderTurn shoulder_turn = ShoulderTurn::kNone;
  double shoulder_turn_angle_deg = 90.0;
  // Giving way: "blocked" is a velocity along e_i, averaged over 1 s, below
  // give_way_speed_m_per_s; "room" is touching at most give_way_max_contacts
  // people; "their way" is the mean desired direction of the people touched.
  GiveWay give_way = GiveWay::kNone;
  double give_way_blocked_s = 3.0;       // issue 19's give-up
  double give_way_speed_m_per_s = 0.1;   // issue 19's give-up
  double give_way_duration_s = 5.0;      // issue 19's give-up
  double give_way_max_contacts = 3.0;    // whole number
  // A reaction time: w_i follows dw/dt = (v_i - w_i) / T, T =
  // drive_reaction_time_s (the exact update for v_i constant over a step,
  // once per step after the integrator; in the checkpoint). The mean delay of
  // this filter is T.
  DriveReaction drive_reaction = DriveReaction::kInstant;
  double drive_reaction_time_s = 0.5;

  // --- Keeping a distance (issue 64; off by default) ------------------------
  // Headway::kTimeGap: s_i the distance to the nearest person ahead along e_i
  // whose centre lies within headway_length_m of e_i's line; the desired
  // speed capped at max(0, (s_i - l) / T), l = headway_length_m, T =
  // headway_time_gap_s; e_i turned by a exp((l - d_ij) / D) away from each
  // person j at d_ij (a = headway_repulsion_strength, D = headway_repulsion_range_m).
  // Defaults: JuPedSim's collision-free speed model (T 1 s, l 0.4 m, a 8, D 0.1 m).
  Headway headway = Headway::kNone;
  double headway_time_gap_s = 1.0;
  double headway_length_m = 0.4;
  double headway_repulsion_strength = 8.0;
  double headway_repulsion_range_m = 0.1;
  // SocialForce::kCircular: on a walking person i from every other person j
  // (walking or fallen) at centre distance d_ij, A exp((r_ij - d_ij)/B) n_ij
  // w(phi_ij), r_ij the sum of the two bodies' bounding radii, n_ij the unit
  // vector from j to i, w = lambda + (1 - lambda)(1 + cos phi_ij)/2 with
  // phi_ij the angle between e_i and the direction to j (people behind count
  // lambda, people ahead 1). Once the bodies' bounding circles overlap the
  // force stays A: the contact forces carry the bodies. Defaults: Helbing,
  // Farkas and Vicsek 2000 (A 2000 N, B 0.08 m), isotropic (lambda 1).
  SocialForce social_force = SocialForce::kNone;
  double social_force_strength_n = 2000.0;
  double social_force_range_m = 0.08;
  double social_force_anisotropy = 1.0;
  // Centrifugal::kGeneralized: on a walking person i moving at v_i from each
  // person j with K_ij = max(0, v_i . e_ij) / |v_i| > 0 (e_ij from i to j;
  // nobody at rest is pushed), -m_i K_ij (eta v0_i + v_ij)^2 / dist_ij e_ij,
  // v_ij = max(0, (v_i - v_j) . e_ij), dist_ij the gap between the two
  // people's ellipses along the line of centres (semi-axes a = a_min + tau_a
  // |v| along the velocity, b = b_max - (b_max - b_min) min(1, |v| / v0)
  // across it). Between r_c - r_eps and r_c it falls to 0, below r_eps it
  // rises to f_m times its value at r_eps (Hermite interpolations; f_m times
  // that value where the ellipses overlap). Defaults: Chraibi et al. 2010
  // (eta 0.28; a_min 0.18 m, tau_a 0.53 s, b_min 0.2 m, b_max 0.25 m) and
  // JuPedSim's (r_c 2 m, r_eps 0.1 m, f_m 3).
  Centrifugal centrifugal = Centrifugal::kNone;
  double centrifugal_strength = 0.28;
  double centrifugal_cutoff_m = 2.0;
  double centrifugal_interpolation_m = 0.1;
  double centrifugal_max_factor = 3.0;
  double centrifugal_a_min_m = 0.18;
  double centrifugal_a_time_s = 0.53;
  double centrifugal_b_min_m = 0.2;
  double centrifugal_b_max_m = 0.25;
  // Anticipation::kTimeToCollision: tau the time until the bounding circles
  // of i and j touch if both keep their velocities (none when they move
  // apart, miss, or already overlap); on i, m_i k e^(-tau/tau0) tau^-2 (2/tau
  // + 1/tau0) (x_ij + v_ij tau) / sqrt(D) (x_ij = x_i - x_j, v_ij = v_i -
  // v_j, D the discriminant of |x_ij + v_ij t| = r_i + r_j), its size at most
  // m_i times anticipation_max_acceleration_m_per_s2, from each person within
  // anticipation_radius_m. Defaults: Karamouzas, Skinner and Guy 2014 (k 1.5
  // m^2, tau0 3 s); the ceiling and the radius are ours.
  Anticipation anticipation = Anticipation::kNone;
  double anticipation_strength_m2 = 1.5;
  double anticipation_horizon_s = 3.0;
  double anticipation_max_acceleration_m_per_s2 = 5.0;
  double anticipation_radius_m = 5.0;
  // How often the anticipation force is evaluated (issue 66): 0, at every
  // step; else at the first step of each interval of this length (t in
  // [k h, (k+1) h)), each person keeping the force per unit mass of that
  // evaluation until the next (multiple time stepping: the slow force on a
  // coarser clock than the contacts, Tuckerman, Berne and Martyna 1992: the
  // force from people metres away changes over tenths of a second, the
  // contacts' over milliseconds).
  double anticipation_interval_s = 0.0;
  // With the clock: the force from people within this centre distance is
  // evaluated at every step (a smooth switch over its last 0.5 m), only the
  // rest on the clock; 0: every pair on the clock.
  double anticipation_near_m = 0.0;
  // A side preference in avoiding (issue 64; 0 off): a walking person turns
  // this share of the braking part of their anticipation force (the part
  // against their own direction e_i, -F.e_i where positive) into a step to
  // their right, (e_y, -e_x) (ERRATA 9's frame, the floor's normal up); a
  // negative value steps to the left. Two people meeting head on both step
  // to their own right and pass left shoulder to left shoulder, as most
  // people do where traffic keeps right (Moussaid et al. 2009; Xiao et al.
  // 2019, about 70 % to the right in circle-antipode experiments).
  double anticipation_side_preference = 0.0;
  // When it acts: always (s B), or scaled by how much the walker is slowed,
  // max(0, 1 - v_i.e_i / v0_i): people walking at their desired speed keep
  // their line, people held up by someone coming the other way step aside.
  SidePreferenceGate anticipation_side_gate = SidePreferenceGate::kAlways;

  // (Bodies: masses in 40-70 kg and rho = 1000 kg/m^2 are the population's,
  // geometry::PopulationOptions; PersonDef holds each person's mass and inertia.)

  // --- Floor --------------------------------------------------------------
  double gravity_m_per_s2 = 9.81;  // for the optional floor slope body force
  SlopeResponse slope_response = SlopeResponse::kBodyForce;

  // --- Time integration ---------------------------------------------------
  Integrator integrator = Integrator::kVelocityVerlet;
  // Time step (s); 0 = chosen by the engine from the stiffest contact (see
  // StableTimeStep). A user-given value above the stability limit is refused.
  double time_step_s = 0.0;
  // Fraction of the integrator's stability limit used when the engine chooses
  // the step: h = safety * 2 / omega_max for velocity Verlet. Chosen for
  // accuracy, not speed: at 0.08 the restitution of head-on collisions is
  // within 2% of epsilon for epsilon in [0.1, 0.5] whatever the phase of the
  // collision within a step, and within 0.5% at half that step
  // (tests/unit/test_engine_physics.cpp; docs/model.md).
  double time_step_safety = 0.08;
  // Adaptive step (TimeStepMode::kAdaptive): the step is the fixed step h
  // (above) times 2^l, l = 0..L, L the largest with 2^L time_step_safety <=
  // adaptive_max_safety. A step 2^l h is taken only while every pair that may
  // touch within two of the largest steps approaches at most as fast as
  // adaptive_reference_speed_m_per_s * err(h) / err(2^l h), err the measured
  // restitution error of a collision at that step (RestitutionErrorAtStep):
  // no collision's velocity error exceeds what the fixed step gives a
  // collision at the reference speed. 0: the fastest desired speed of the
  // world's people.
  TimeStepMode time_step_mode = TimeStepMode::kFixed;
  double adaptive_max_safety = 0.32;
  double adaptive_reference_speed_m_per_s = 0.0;
  // Sleeping (issue 66; off by default: 0): a walking person who has been
  // still (speed and rim speed below sleep_speed_m_per_s) for sleep_time_s
  // falls asleep: not integrated, the contacts with other sleepers and walls
  // carried unchanged from step to step, the drive frozen at the force that
  // holds the mean load (contacts, external force) the person bore while
  // still. A sleeper wakes when its load moves from that mean by more than
  // sleep_wake_force_n (or its torque by that force at the body's farthest
  // core point), or when anything about it changes (target, desired speed,
  // external force, state, its group's drive, the model's parameters, a wall
  // switched). docs/model.md, "Sleeping"; engine/src/stage_sleep.cpp.
  double sleep_speed_m_per_s = 0.0;
  double sleep_time_s = 1.0;
  double sleep_wake_force_n = 20.0;

  // Returns false and fills *error with "name = value, expected in [min,
  // max]" if a value is outside its range in the parameter table
  // (parameter_table.hpp, the one place the ranges are written).
  bool IsValid(std::string* error) const;
};

// Normal damping rate gamma_n (1/s) that gives restitution epsilon for a
// contact of stiffness k and effective mass m_ij, by inverting eq. (19):
//   gamma = 2 L sqrt(k / m) / sqrt(pi^2 + L^2),  L = -ln(epsilon)
// (ERRATA 2), written as RestitutionDampingFactor(epsilon) * sqrt(k / m): the
// engine computes the factor once per run and the rest per contact
// (ContactLaw::PairRates).
double RestitutionDampingFactor(double restitution);
double DampingRateFromRestitution(double restitution, double stiffness_n_per_m, double mass_kg);
// Eq. (19) itself: restitution of a linear spring-dashpot contact.
double RestitutionFromDampingRate(double gamma_per_s, double stiffness_n_per_m, double mass_kg);

}  // namespace crowdrecon::engine
