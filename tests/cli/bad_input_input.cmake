# Bad inputs to the input layer (JSON, files, limits, option values, run
# files): each must end in exit status 2 (or CLI11's option status) with a
# message naming the file, the path or row, the value and what was expected,
# writing nothing and changing no input (tests/cli/expect_refused.sh).
set(REFUSED ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect_refused.sh)
function(crowdrecon_refused_test name status regex)
  add_test(NAME cli.bad_input.${name}
           COMMAND bash ${REFUSED} ${status} ${regex} ${ARGN}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endfunction()
set(EXE $<TARGET_FILE:crowdrecon>)
set(S tests/data/scenarios)

# --- JSON ----------------------------------------------------------------------
crowdrecon_refused_test(json.deep_nesting 2 "deep.json:1:[0-9]+: objects and arrays nested more than 100 levels deep"
  --nested 100000 deep.json -- ${EXE} simulate @TMP@/deep.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.duplicate_key 2
  "bad-duplicate-key.json:10:[0-9]+: /run/duration_s: key given twice \\(first at line 8 with value 0.5, again at line 10 with value 0.2\\)"
  -- ${EXE} simulate ${S}/bad-duplicate-key.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.duplicate_key_in_sweep_scenario 2 "bad-duplicate-key.json:10:[0-9]+: /run/duration_s: key given twice"
  -- ${EXE} sweep tests/data/sweeps/bad-duplicate-scenario-key.json -o @OUT@/sweep -q)
crowdrecon_refused_test(json.number_overflow 2
  "bad-number-overflow.json:7:[0-9]+: number 1e400 is beyond the range of a double .*expected a finite number"
  -- ${EXE} simulate ${S}/bad-number-overflow.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.unsigned_count 2
  "bad-count-unsigned.json: /population/count: value 18446744073709551615 is out of range. expected an integer in \\[0, 200000\\]"
  -- ${EXE} simulate ${S}/bad-count-unsigned.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.long_unknown_key_shortened 2 "long.json: /: unknown key\\(s\\) \"k{57}\\.\\.\\.\" "
  --long-key 10000000 long.json -- ${EXE} shape @TMP@/long.json -o @OUT@/body.json)

# --- a folder given as a file --------------------------------------------------
crowdrecon_refused_test(dir.scenario 2 "scenarios: is a directory. expected a scenario file"
  -- ${EXE} simulate ${S} -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(dir.venue 2 "venues: is a directory. expected a venue file"
  -- ${EXE} venue check tests/data/venues)
crowdrecon_refused_test(dir.sweep 2 "sweeps: is a directory. expected a sweep file"
  -- ${EXE} sweep tests/data/sweeps -o @OUT@/sweep -q)
crowdrecon_refused_test(dir.wkt 2 "venues: is a directory. expected a WKT file"
  -- ${EXE} venue import tests/data/venues --format wkt -o @OUT@/v.json)
crowdrecon_refused_test(dir.dxf 2 "venues: is a directory. expected a DXF file"
  -- ${EXE} venue import tests/data/venues --format dxf -o @OUT@/v.json)
crowdrecon_refused_test(dir.body 2 "bodies: is a directory. expected a JSON file"
  -- ${EXE} population --body tests/data/bodies -o @OUT@/p.json)
crowdrecon_refused_test(dir.anthropometry 2 "bodies: is a directory. expected an ANSUR II extract"
  -- ${EXE} population --mode anthropometric --anthropometry tests/data/bodies -o @OUT@/p.json)
crowdrecon_refused_test(device.scenario 2 "/dev/zero: is a device or socket, not a file. expected a scenario file"
  -- ${EXE} simulate /dev/zero -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(device.venue 2 "/dev/null: is a device or socket, not a file. expected a venue file"
  -- ${EXE} venue check /dev/null)
crowdrecon_refused_test(dir.scenario_body_reference 2 "bad-body-directory.json: /population/body/reference: \".*bodies\" is a directory. expected a body file"
  -- ${EXE} simulate ${S}/bad-body-directory.json -o @OUT@/x.sqlite -q)

# --- limits ----------------------------------------------------------------------
crowdrecon_refused_test(limit.scenario_count 2
  "bad-count-limit.json: /population/count: value 1000000 is out of range. expected an integer in \\[0, 200000\\]"
  -- ${EXE} simulate ${S}/bad-count-limit.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(limit.density_in_wrong_units 2
  "bad-density-scale.json: /population/density_per_m2: 2 /m\\^2 over 39000000 m\\^2 gives 78000000 people. expected at most 200000 \\(check the venue's scale"
  -- ${EXE} simulate ${S}/bad-density-scale.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(limit.population_count option "--count: value 1000000 is out of range. expected a whole number in \\[1, 200000\\]"
  -- ${EXE} population --count 1000000 -o @OUT@/p.json)
crowdrecon_refused_test(limit.population_count_negative option "--count: value -5 is out of range"
  -- ${EXE} population --count -5 -o @OUT@/p.json)
crowdrecon_refused_test(limit.sweep_runs 2
  "bad-too-many-runs.json: /: the sweep has 1000000 runs \\(1 variant\\(s\\) x 1000 \\(population.density_per_m2\\) x 1000 \\(population.counter_flow_fraction\\) x 1 seed\\(s\\)\\). expected at most 100000"
  -- ${EXE} sweep tests/data/sweeps/bad-too-many-runs.json -o @OUT@/sweep -q)
crowdrecon_refused_test(limit.sweep_runs_never_wrap 2 "bad-runs-overflow.json: /: the sweep has more than 10\\^19 runs"
  -- ${EXE} sweep tests/data/sweeps/bad-runs-overflow.json -o @OUT@/sweep -q)

# --- option values -----------------------------------------------------------------
foreach(case
    "simulate_stop_after_negative~--stop-after: value -1 is out of range. expected a number in \\[0, 1000000000\\] s~simulate;${S}/hallway-short.json;-o;@OUT@/x.sqlite;--stop-after;-1"
    "simulate_stop_after_nan~--stop-after: value nan is not finite~simulate;${S}/hallway-short.json;-o;@OUT@/x.sqlite;--stop-after;nan"
    "simulate_threads~--threads: \"two\" is not a whole number. expected a whole number in \\[0, 1024\\]~simulate;${S}/hallway-short.json;-o;@OUT@/x.sqlite;--threads;two"
    "analyze_transient~--transient: value -1 is out of range. expected a number in \\[0, 1000000\\] s~analyze;@TMP@/none.sqlite;--transient;-1"
    "analyze_digest_write~--write excludes --digest~analyze;@TMP@/none.sqlite;--digest;--write"
    "analyze_digest_json~--json excludes --digest~analyze;@TMP@/none.sqlite;--digest;--json;@OUT@/a.json"
    "render_fps_nan~--fps: value nan is not finite. expected a number in \\[0.01, 1000\\]~render;@TMP@/none.sqlite;-o;@OUT@/f;--fps;nan"
    "render_width~--width: value 10 is out of range. expected a whole number in \\[320, 8000\\]~render;@TMP@/none.sqlite;-o;@OUT@/f;--width;10"
    "render_force_scale~--force-scale: value -3 is out of range~render;@TMP@/none.sqlite;-o;@OUT@/f;--force-scale;-3"
    "shape_vertices~--vertices: value 2 is out of range. expected a whole number in \\[3, 1000\\]~shape;venues/bodies/thorax-reference.json;-o;@OUT@/b.json;--vertices;2"
    "shape_radius~--radius: value -1 is out of range. expected a number in \\[0.0001, 1\\] m~shape;venues/bodies/thorax-reference.json;-o;@OUT@/b.json;--radius;-1"
    "population_female_fraction~--female-fraction: value 2 is out of range. expected a number in \\[0, 1\\]~population;--female-fraction;2;-o;@OUT@/p.json"
    "population_seed~--seed: value -1 is out of range. expected a whole number in \\[0, 4611686018427387904\\]~population;--seed;-1;-o;@OUT@/p.json"
    "body_reference_female_fraction~--female-fraction: value nan is not finite~body;reference;--female-fraction;nan;-o;@OUT@/b.json;--outline;@OUT@/o.json"
    "venue_import_scale~--scale: value -1 is out of range. expected a number in \\[1e-09, 1000000000\\] m per unit~venue;import;tests/data/venues/room.wkt;-o;@OUT@/v.json;--scale;-1"
    "venue_import_simplify~--simplify-px: value -1 is out of range. expected a number in \\[0, 100\\] px~venue;import;tests/data/venues/room-50ppm.png;-o;@OUT@/v.json;--pixels-per-metre;50;--simplify-px;-1"
    "venue_import_ppm~--pixels-per-metre: value 0 is out of range~venue;import;tests/data/venues/room-50ppm.png;-o;@OUT@/v.json;--pixels-per-metre;0"
    "venue_import_threshold~--dark-threshold: value 300 is out of range. expected a whole number in \\[1, 255\\]~venue;import;tests/data/venues/room-50ppm.png;-o;@OUT@/v.json;--pixels-per-metre;50;--dark-threshold;300"
    "venue_check_grid~--grid-spacing: value inf is not finite~venue;check;tests/data/venues/room.json;--grid-spacing;inf"
    "sweep_jobs~--jobs: value -1 is out of range. expected a whole number in \\[0, 4096\\]~sweep;tests/data/sweeps/tiny.json;-o;@OUT@/s;--jobs;-1"
    "sweep_stop_after_runs~--stop-after-runs: \"1.5\" is not a whole number~sweep;tests/data/sweeps/tiny.json;-o;@OUT@/s;--stop-after-runs;1.5"
    "sweep_log_every~--log-every: value -1 is out of range. expected a number in \\[0, 10000000\\] s~sweep;tests/data/sweeps/tiny.json;-o;@OUT@/s;--log-every;-1"
    "simulate_log_every_nan~--log-every: value nan is not finite~simulate;${S}/hallway-short.json;-o;@OUT@/x.sqlite;--log-every;nan")
  string(REPLACE "~" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 regex)
  list(SUBLIST parts 2 -1 cmd)
  crowdrecon_refused_test(option.${name} option "${regex}" -- ${EXE} ${cmd})
endforeach()

# --- damaged run files (a copy of the render fixture's run, changed with sqlite3) --
set(RUN ${CMAKE_CURRENT_BINARY_DIR}/render-data/run.sqlite)
foreach(case
    "pos_x_text_analyze~UPDATE trajectory_data SET pos_x = 'abc' WHERE frame = 3 AND id = 2~table trajectory_data, row frame 3, id 2, column pos_x: found text abc. expected a number in \\[-20000000, 20000000\\]~analyze"
    "pos_x_text_render~UPDATE trajectory_data SET pos_x = 'abc' WHERE frame = 0 AND id = 2~table trajectory_data, row frame 0, id 2, column pos_x: found text abc. expected a number~render"
    "pos_y_huge_analyze~UPDATE trajectory_data SET pos_y = 1e308 WHERE frame = 5 AND id = 4~table trajectory_data, row frame 5, id 4, column pos_y: found real 1.0e\\+308. expected a number in~analyze"
    "pos_y_huge_render~UPDATE trajectory_data SET pos_y = 1e308 WHERE frame = 0 AND id = 4~table trajectory_data, row frame 0, id 4, column pos_y: found real 1.0e\\+308~render"
    "ori_render~UPDATE trajectory_data SET ori_x = 7 WHERE frame = 0 AND id = 1~table trajectory_data, row frame 0, id 1, column ori_x: found (integer|real) 7(.0)?. expected a number in \\[-1.000001, 1.000001\\]~render"
    "velocity_text_analyze~UPDATE person_state SET vel_x = 'fast' WHERE frame = 2 AND id = 3~table person_state, row frame 2, id 3, column vel_x: found text fast~analyze"
    "load_negative_analyze~UPDATE person_state SET load_n = -5 WHERE frame = 2 AND id = 3~table person_state, row frame 2, id 3, column load_n: found (integer|real) -5(.0)?. expected a number in \\[0, 1e\\+12\\]~analyze"
    "time_text_analyze~UPDATE frame_time SET time_s = 'later' WHERE frame = 4~table frame_time, row frame 4, column time_s: found text later~analyze"
    "time_text_render~UPDATE frame_time SET time_s = 'later' WHERE frame = 0~table frame_time, row frame 0, column time_s: found text later~render"
    "group_analyze~UPDATE person SET grp = 99999 WHERE id = 5~table person, row id 5, column grp: found integer 99999. expected a whole number in \\[0, 1023\\]~analyze"
    "person_shape_render~UPDATE person SET shape = 40 WHERE id = 5~table person, row id 5, column shape: found integer 40. expected a whole number in \\[0, 0\\]~render"
    "contact_force_render~UPDATE contact SET normal_force_n = 'x' WHERE rowid = (SELECT MIN(rowid) FROM contact)~table contact, row frame [0-9]+, rowid [0-9]+, column normal_force_n: found text x~render"
    "shape_vertices_render~UPDATE shape SET vertices = 'not json'~table shape, row id [0-9]+, column vertices: malformed point list~render"
    "wall_radius_render~UPDATE wall SET radius_m = -1~table wall, row id [0-9]+, column radius_m: found (integer|real) -1(.0)?. expected a number in \\[0, 10\\]~render"
    "time_step_render~INSERT OR REPLACE INTO run VALUES('time_step_s', 'abc')~table run, row key time_step_s, column value: found \"abc\". expected a number in \\[0, 1\\]~render")
  string(REPLACE "~" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 sql)
  list(GET parts 2 regex)
  list(GET parts 3 command)
  if(command STREQUAL "render")
    set(cmd render @TMP@/run.sqlite -o @OUT@/frames)
  else()
    set(cmd analyze @TMP@/run.sqlite --json @OUT@/a.json)
  endif()
  crowdrecon_refused_test(run_file.${name} 2 "run.sqlite: ${regex}" --corrupt ${RUN} "${sql}" -- ${EXE} ${cmd})
  set_tests_properties(cli.bad_input.run_file.${name} PROPERTIES FIXTURES_REQUIRED render_data)
endforeach()

# A figure of an unknown format is refused before the observation is written (issue 65, Q09).
crowdrecon_refused_test(observe_figure_format_first 2 "--figure .*f.txt: .*picture format"
  -- ${EXE} observe trajectories ${RUN} --spec venues/madrid-arena/observations/hallway.json -o @OUT@/o.json
  --figure @OUT@/f.txt)
set_tests_properties(cli.bad_input.observe_figure_format_first PROPERTIES FIXTURES_REQUIRED render_data)

# A file output into a folder that does not exist is refused before any work
# (issue 65: timeline --scores failed after writing its figure).
crowdrecon_refused_test(output_folder_missing 2 "--json .*missing/a.json: its folder .*missing does not exist"
  -- ${EXE} analyze ${RUN} --json @OUT@/missing/a.json)
set_tests_properties(cli.bad_input.output_folder_missing PROPERTIES FIXTURES_REQUIRED render_data)

# A browser given that is not there is refused before any work (issue 65, M15, K41).
crowdrecon_refused_test(report_chromium_missing 2 "--chromium /nonexistent/chrome: no such program"
  -- ${EXE} report ${RUN} --chromium /nonexistent/chrome -o @OUT@/r)
set_tests_properties(cli.bad_input.report_chromium_missing PROPERTIES FIXTURES_REQUIRED render_data)
crowdrecon_refused_test(validate_chromium_missing 2 "--chromium /nonexistent/chrome: no such program"
  -- ${EXE} validate venues/validation/tests/rimea-01-corridor.json --chromium /nonexistent/chrome -o @OUT@/v)

# --- run.stop_when_settled (issue 19) ---------------------------------------------
crowdrecon_refused_test(json.settle_not_an_object 2
  "bad-settle-not-object.json: /run/stop_when_settled: expected an object \\{\"frozen_window_s\": \\.\\.\\., \"lanes_window_s\": \\.\\.\\.\\} \\(may be empty: the defaults\\), found true"
  -- ${EXE} simulate ${S}/bad-settle-not-object.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.settle_window_range 2
  "bad-settle-window.json: /run/stop_when_settled/lanes_window_s: value 0.2 is out of range.*expected a number in \\[1, 3600\\]"
  -- ${EXE} simulate ${S}/bad-settle-window.json -o @OUT@/x.sqlite -q)
crowdrecon_refused_test(json.settle_unknown_key 2
  "bad-settle-unknown.json: /run/stop_when_settled: unknown key\\(s\\) \"lanes_window\""
  -- ${EXE} simulate ${S}/bad-settle-unknown.json -o @OUT@/x.sqlite -q)
