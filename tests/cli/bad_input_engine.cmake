# Engine hardening (issue 17): walls that nobody goes through, a time step
# from every stiffness, rooms walled all round. Each test runs a scenario
# of tests/data/scenarios with tests/cli/engine_run_check.sh, which checks the
# exact exit status, the message, the run file and that the input is unchanged.
set(ENGINE_RUN_CHECK ${CMAKE_CURRENT_SOURCE_DIR}/cli/engine_run_check.sh)
function(crowdrecon_engine_run_test name scenario rc regex)
  add_test(NAME cli.engine.${name}
           COMMAND bash ${ENGINE_RUN_CHECK} $<TARGET_FILE:crowdrecon> ${CMAKE_CURRENT_SOURCE_DIR}/data/scenarios/${scenario} ${rc} ${regex} ${ARGN}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endfunction()

# People sprinting into a wall at 10 m/s: the run stops when a core crosses
# the wall line (it used to end "complete" with people 15 m beyond the wall),
# with the state saved and a numerical_failure event.
crowdrecon_engine_run_test(wall.sprint_through_wall bad-sprint-into-wall.json 2
  "bad-sprint-into-wall.json|run.sqlite: the run went numerically wrong: person [0-9]+ went through wall 0 at t = [0-9.]+ s near \\([0-9.]+, [0-9.]+\\), centre at .*the core crossed the wall line.*state is saved in .*run.sqlite.failed-state"
  exists:.failed-state
  "sql:SELECT kind FROM event=>^numerical_failure$"
  "sql:SELECT value FROM run WHERE key = 'status'=>^failed: person [0-9]+ went through wall 0"
  "sql:SELECT count(*) FROM trajectory_data WHERE pos_x > 6=>^0$")

# Rooms walled all round, by one polygon wall or by four polylines that
# close it, with no exit: 20 people are placed and push east for 2 s (they
# used to be refused: "cannot place person 1 of 20 ... the density is too high").
foreach(form polygon polylines)
  crowdrecon_engine_run_test(closed_room.${form} closed-room-${form}.json 0 "status complete"
    "sql:SELECT value FROM run WHERE key = 'status'=>^complete$"
    "sql:SELECT count(*) FROM run WHERE key = 'time_step_warning'=>^0$"
    "sql:SELECT count(*) FROM trajectory_data WHERE pos_x < 0 OR pos_x > 6 OR pos_y < 0 OR pos_y > 4=>^0$")
endforeach()

# k_t = 1e7 N/m (100 k_n): the step follows it, so the placement relaxes (it
# used to fail with "placement failed while relaxing (the density may be too high)").
crowdrecon_engine_run_test(time_step.stiff_tangential stiff-tangential.json 0 "status complete"
  "sql:SELECT value FROM run WHERE key = 'status'=>^complete$")

# A user's step between the engine's accurate step and the stability limit
# runs, with a warning on stderr and in the run table naming the restitution error.
crowdrecon_engine_run_test(time_step.long_step_warns long-time-step.json 0
  "crowdrecon: warning: .*long-time-step.json: /model/time_step_s: the step 0.005 s is [0-9.]+ times the engine's accurate step [0-9.e-]+ s \\(stability limit [0-9.e-]+ s\\): collisions then rebound with a restitution off by up to [0-9.]+ %"
  "sql:SELECT value FROM run WHERE key = 'time_step_warning'=>restitution off by up to [0-9.]+ %")
