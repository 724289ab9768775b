# Command-line tests (see expect.sh). Arguments may use @TMP@ for a scratch dir.
crowdrecon_cli_test(help ok "shape" --help)

# --- venues ------------------------------------------------------------------
crowdrecon_cli_test(venue.check.hallway_periodic ok "periodic: along \\(1, 0\\), period 12 m"
                    venue check venues/madrid-arena/hallway-periodic.json --picture @TMP@/hallway-periodic.png)
crowdrecon_cli_test(venue.check.hallway_open ok "walkable area: 36.00 m2 in 1 part"
                    venue check venues/madrid-arena/hallway-open.json --picture @TMP@/hallway-open.svg)
crowdrecon_cli_test(venue.check.ground_floor ok "walkable area: 1925.00 m2"
                    venue check venues/madrid-arena/ground-floor.json --picture @TMP@/ground-floor.png)
crowdrecon_cli_test(venue.check.wuppertal_bottleneck ok "walkable area: 64.27 m2 in 1 part"
                    venue check venues/juelich/wuppertal-bottleneck.json --picture @TMP@/wuppertal-bottleneck.png)
crowdrecon_cli_test(venue.check.hallway_antechambers ok "walkable area: 120.00 m2 in 1 part"
                    venue check venues/madrid-arena/hallway-antechambers.json --picture @TMP@/antechambers.png)
crowdrecon_cli_test(venue.check.verification_gate_corridor ok "walkable area: 48.00 m2 in 1 part"
                    venue check venues/verification/gate-corridor.json --picture @TMP@/gate-corridor.png)
crowdrecon_cli_test(venue.check.verification_sloping_corridor ok "slope: .*0.1"
                    venue check venues/verification/sloping-corridor.json)
crowdrecon_cli_test(venue.check.itaewon_alley ok "slope: gradient 0.1405 \\(14.1 %, 8.0 degrees\\) downhill toward \\(0, -1\\), enabled, inside a region of 4 points"
                    venue check venues/itaewon/alley.json)
crowdrecon_cli_test(venue.check.capacity ok "capacity: 183 persons at 4.7 /m2, 234 at 6.0 /m2"
                    venue check tests/data/venues/room.json)
crowdrecon_cli_test(venue.import.wkt ok "39.00 m2 walkable in 1 part\\(s\\), 1 obstacle"
                    venue import tests/data/venues/room.wkt -o @TMP@/room.json)
crowdrecon_cli_test(venue.import.wkt_multipolygon ok "20.00 m2 walkable in 2 part"
                    venue import tests/data/venues/two-rooms.wkt -o @TMP@/two.json --name "two rooms")
crowdrecon_cli_test(venue.import.dxf ok "39.00 m2 walkable in 1 part\\(s\\), 1 obstacle"
                    venue import tests/data/venues/room.dxf -o @TMP@/room.json)
crowdrecon_cli_test(venue.import.image ok "39.00 m2 walkable in 1 part\\(s\\), 1 obstacle"
                    venue import tests/data/venues/room-50ppm.png -o @TMP@/room.json --pixels-per-metre 50
                    --seed 3,1)

# Invalid venues: each message names the file, the JSON path and the problem.
foreach(case
    "self-intersecting|/walkable_area/0: outer ring is self-intersecting"
    "obstacle-outside|/obstacles/0/polygon: obstacle .kiosk. near .* lies outside the walkable area"
    "overlapping-obstacles|/obstacles/1/polygon: obstacles .bar.* and .stage. overlap"
    "obstacle-crosses-boundary|/obstacles/0/polygon: obstacle .pillar. meets the boundary"
    "exit-outside|/exits/1/segment: exit point \\(30, 0\\) is 20 m outside the walkable area"
    "unknown-key|: /: unknown key.s. .exitz."
    "wrong-type|/periodic/0/period_m: expected a number .* found .ten."
    "gradient|/slope/gradient: value -0.025 is out of range"
    "empty-area|/walkable_area: the walkable area is empty"
    "syntax|:3:9: invalid JSON"
    "target|/targets/0/exit: target .leave. names exit .main., which does not exist"
    "period|/periodic/0/period_m: period 12 m differs"
    "duplicate-id|/exits/1/id: id .door. is used twice"
    "zero-direction|/targets/0/direction: the direction .* has zero length")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 regex)
  crowdrecon_cli_test(venue.check.bad_${name} fail "bad-${name}.json.*${regex}"
                      venue check tests/data/venues/bad-${name}.json)
endforeach()
crowdrecon_cli_test(venue.check.missing_file fail "no-such-venue.json: cannot open venue file"
                    venue check tests/data/venues/no-such-venue.json)
crowdrecon_cli_test(venue.import.bad_wkt_syntax fail "bad-syntax.wkt:2:33: invalid WKT: expected a number but found 'x'"
                    venue import tests/data/venues/bad-syntax.wkt -o @TMP@/x.json)
crowdrecon_cli_test(venue.import.bad_wkt_unclosed fail "bad-unclosed.wkt:1:10: invalid WKT: ring is not closed"
                    venue import tests/data/venues/bad-unclosed.wkt -o @TMP@/x.json)
crowdrecon_cli_test(venue.import.bad_dxf_open fail "bad-open.dxf: no closed region found"
                    venue import tests/data/venues/bad-open.dxf -o @TMP@/x.json)
crowdrecon_cli_test(venue.import.image_needs_scale fail "give --pixels-per-metre"
                    venue import tests/data/venues/room-50ppm.png -o @TMP@/x.json)
crowdrecon_cli_test(venue.import.bad_seed fail "--seed .3x1.: expected two numbers X,Y"
                    venue import tests/data/venues/room-50ppm.png -o @TMP@/x.json --pixels-per-metre 50 --seed 3x1)
crowdrecon_cli_test(venue.import.unknown_extension fail "cannot tell the format from the extension"
                    venue import tests/data/venues/room.json -o @TMP@/x.json)

# --- bodies (docs/bodies.md) ---------------------------------------------------
crowdrecon_cli_test(shape.image ok "vertices: 18, sphero-radius 0.05 m"
                    shape tests/data/bodies/ellipse-1000ppm.png --scale ppm:1000 -o @TMP@/ellipse.json
                    --picture @TMP@/ellipse.png)
crowdrecon_cli_test(shape.image_sternum ok "scale: sternum:0.2 "
                    shape tests/data/bodies/ellipse-1000ppm.png -o @TMP@/ellipse.json --picture @TMP@/e.svg)
crowdrecon_cli_test(shape.reference ok "Hausdorff distance outline - swept shape: 0.00"
                    shape venues/bodies/thorax-reference.json --vertices 18 --radius 0.05 -o @TMP@/thorax.json)
crowdrecon_cli_test(shape.light_region ok "note: the light region touches the image border"
                    shape tests/data/bodies/blank.png --region light -o @TMP@/b.json)
crowdrecon_cli_test(population.paper ok "mass: 4[0-9]\\.[0-9]+ \\.\\. [67][0-9]\\.[0-9]+ kg"
                    population --mode paper --count 50 --seed 3 -o @TMP@/pop.json --picture @TMP@/pop.png)
crowdrecon_cli_test(population.anthropometric ok "bodies built: [0-9]+ distinct"
                    population --mode anthropometric --count 12 --seed 3 --female-fraction 0.5
                    -o @TMP@/pop.json)
crowdrecon_cli_test(population.circle ok "population: circle, 10 people"
                    population --mode circle --count 10 --seed 3 -o @TMP@/pop.json)
crowdrecon_cli_test(population.bad_mode fail "--mode: unknown population mode \"crowd\""
                    population --mode crowd --count 10 -o @TMP@/pop.json)
crowdrecon_cli_test(body.reference ok "wrote @TMP@/thorax-18.json|thorax-18.json"
                    body reference --outline @TMP@/thorax-reference.json -o @TMP@/thorax-18.json)

# Invalid outlines and options: each message names the file or option and the problem.
foreach(case
    "empty_image|tests/data/bodies/empty.png: not a readable image|tests/data/bodies/empty.png"
    "no_region|blank.png: no dark region|tests/data/bodies/blank.png"
    "too_few_points|two-points.csv: too few points \\(2 distinct\\)|tests/data/bodies/two-points.csv"
    "self_intersecting|bowtie.json: the outline intersects itself \\(edge 0|tests/data/bodies/bowtie.json"
    "too_thin|thin-strip.json: outline too thin for the sphero-radius|tests/data/bodies/thin-strip.json"
    "missing_file|missing.json: cannot open file|tests/data/bodies/missing.json"
    "bad_json|bad-syntax.json:2:1: invalid JSON|tests/data/bodies/bad-syntax.json")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 regex)
  list(GET parts 2 file)
  crowdrecon_cli_test(shape.invalid.${name} fail "${regex}" shape ${file} -o @TMP@/body.json)
endforeach()
crowdrecon_cli_test(shape.invalid.vertices fail "--vertices: value 2 is out of range. expected a whole number in \\[3, 1000\\]"
                    shape venues/bodies/thorax-reference.json --vertices 2 -o @TMP@/body.json)
crowdrecon_cli_test(shape.invalid.radius fail "--radius: value -0.05 is out of range. expected a number in \\[0.0001, 1\\] m"
                    shape venues/bodies/thorax-reference.json --radius -0.05 -o @TMP@/body.json)
crowdrecon_cli_test(shape.invalid.scale fail "--scale: unknown scale rule \"width\""
                    shape venues/bodies/thorax-reference.json --scale width:0.3 -o @TMP@/body.json)
crowdrecon_cli_test(shape.invalid.front fail "--front: unknown front axis \"up\""
                    shape venues/bodies/thorax-reference.json --front up -o @TMP@/body.json)

# --- render (viz/render_run.hpp) ----------------------------------------------
# Run files written by crowdrecon_make_test_run (tests/tools) before these
# tests run (fixture render_data): run.sqlite, 12 people in counter-flow with
# the 18-vertex thorax, 21 frames (0-2 s) with contacts; empty.sqlite, no frame.
set(render_data ${CMAKE_CURRENT_BINARY_DIR}/render-data)
add_test(NAME cli.render.make_data
         COMMAND crowdrecon_make_test_run ${render_data} ${PROJECT_SOURCE_DIR}/venues/bodies/thorax-18.json)
set_tests_properties(cli.render.make_data PROPERTIES FIXTURES_SETUP render_data)
crowdrecon_cli_test(render.first_last ok "video: .*run\\.avi \\(MJPG, 10 fps\\)"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames first,last --width 960
                    --video @TMP@/run.avi --svg)
crowdrecon_cli_test(render.first_last_size ok "rendered 2 frame\\(s\\), 0 to 20, 960 x [0-9]+ px"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames first,last --width 960)
crowdrecon_cli_test(render.every ok "rendered 5 frame\\(s\\), 0 to 20"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames every:5 --force-scale 20)
crowdrecon_cli_test(render.time_range ok "rendered 6 frame\\(s\\), 5 to 10"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames 0.5:1)
crowdrecon_cli_test(render.mp4 ok "video: .*run\\.(mp4 \\(mp4v|avi \\(MJPG), 5 fps\\)"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames every:2 --video @TMP@/run.mp4)
crowdrecon_cli_test(render.missing_file fail "no-such-run.sqlite: run file does not exist"
                    render ${render_data}/no-such-run.sqlite -o @TMP@/frames)
crowdrecon_cli_test(render.not_a_run fail "thorax-18.json: not a crowdrecon run file"
                    render venues/bodies/thorax-18.json -o @TMP@/frames)
crowdrecon_cli_test(render.empty_run fail "empty.sqlite: the run has no frames to draw"
                    render ${render_data}/empty.sqlite -o @TMP@/frames)
crowdrecon_cli_test(render.frame_not_in_run fail "--frames \"0,99\": frame 99 is not in the run \\(the run has 21 frames, 0 to 20\\)"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames 0,99)
crowdrecon_cli_test(render.bad_every fail "--frames \"every:0\": every:N needs a whole number N >= 1"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames every:0)
crowdrecon_cli_test(render.bad_time_range fail "--frames \"2:1\": the time range ends \\(1 s\\) before it starts \\(2 s\\)"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames 2:1)
crowdrecon_cli_test(render.empty_time_range fail "no frame lies between 5 s and 6 s \\(the run covers 0 s to 2(\\.[0-9]+)? s\\)"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames 5:6)
crowdrecon_cli_test(render.unwritable_output fail "expect.sh/frames: cannot create the output folder"
                    render ${render_data}/run.sqlite -o tests/cli/expect.sh/frames)
crowdrecon_cli_test(render.bad_video fail "--video .*run.gif: unknown video format \".gif\", expected .mp4 or .avi"
                    render ${render_data}/run.sqlite -o @TMP@/frames --video @TMP@/run.gif)
crowdrecon_cli_test(render.bad_width fail "--width: value 100 is out of range. expected a whole number in \\[320, 8000\\]"
                    render ${render_data}/run.sqlite -o @TMP@/frames --width 100)
crowdrecon_cli_test(render.window ok "window: \\(0, 0\\) to \\(1.2, 1.5\\) m"
                    render ${render_data}/run.sqlite -o @TMP@/frames --frames last --width 800 --window 0,0,1.2,1.5)
crowdrecon_cli_test(render.bad_window fail "--window \"0,0,1\": 3 numbers. expected x0,y0,x1,y1 in metres"
                    render ${render_data}/run.sqlite -o @TMP@/frames --window 0,0,1)
get_property(render_tests DIRECTORY PROPERTY TESTS)
list(FILTER render_tests INCLUDE REGEX "^cli\\.render\\.")
list(REMOVE_ITEM render_tests cli.render.make_data)
set_tests_properties(${render_tests} PROPERTIES FIXTURES_REQUIRED render_data)

# --- analyze (analysis/run_analysis.hpp) ---------------------------------------
# The 2 s counter-flow run of the render tests: too short for a regime.
crowdrecon_cli_test(analyze.short_run ok "regime: unclassified \\(run too short: 2.0 s"
                    analyze ${render_data}/run.sqlite --json @TMP@/a.json)
crowdrecon_cli_test(analyze.full_report ok "measurement line: middle of the walkable area, across group 0's direction \\(1.5, 0\\) - \\(1.5, 1.5\\), forward \\(1, 0\\)"
                    analyze ${render_data}/run.sqlite --full --transient 0)
crowdrecon_cli_test(analyze.missing_file fail "no-such-run.sqlite: run file does not exist"
                    analyze ${render_data}/no-such-run.sqlite)
crowdrecon_cli_test(analyze.not_a_run fail "thorax-18.json: not a crowdrecon run file"
                    analyze venues/bodies/thorax-18.json)
crowdrecon_cli_test(analyze.empty_run fail "empty.sqlite: the run has 0 frame\\(s\\). the analysis needs at least 2"
                    analyze ${render_data}/empty.sqlite)
crowdrecon_cli_test(analyze.bad_line fail "--line \"1,2,3\": expected four numbers X1,Y1,X2,Y2"
                    analyze ${render_data}/run.sqlite --line 1,2,3)
set_tests_properties(cli.analyze.short_run cli.analyze.full_report cli.analyze.missing_file cli.analyze.empty_run
                     cli.analyze.bad_line PROPERTIES FIXTURES_REQUIRED render_data)
# --write stores the results in (a copy of) the run file.
add_test(NAME cli.analyze.write
         COMMAND bash -c "d=$(mktemp -d) && cp \"$1\" \"$d/r.sqlite\" && \"$0\" analyze \"$d/r.sqlite\" --write >/dev/null && sqlite3 \"$d/r.sqlite\" \"SELECT value FROM run WHERE key = 'regime'\" | grep -qx unclassified && test $(sqlite3 \"$d/r.sqlite\" 'SELECT COUNT(*) FROM metric_summary') -gt 20; rc=$?; rm -rf \"$d\"; exit $rc"
                 $<TARGET_FILE:crowdrecon> ${render_data}/run.sqlite)
set_tests_properties(cli.analyze.write PROPERTIES FIXTURES_REQUIRED render_data)

# --- export (runfile/trajectory_export.hpp) --------------------------------------
# The render tests' run is periodic along x (a 3 m box) and nobody passes a
# seam in its 2 s; python/test_export_periodic.py measures a run with cuts.
crowdrecon_cli_test(export.periodic_run ok "periodic box x in \\[0, 3\\) m: 0 split\\(s\\) at its seams, 12 ids"
                    export ${render_data}/run.sqlite -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.empty_run ok "export: 0 rows in 0 frames, 0 people"
                    export ${render_data}/empty.sqlite -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.missing_file fail "no-such-run.sqlite: no such file. expected a run file \\(.sqlite\\) written by `crowdrecon simulate`"
                    export ${render_data}/no-such-run.sqlite -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.not_a_run fail "thorax-18.json: is a JSON file, not a crowdrecon run file. expected a run file"
                    export venues/bodies/thorax-18.json -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.sweep_results_not_a_run fail "results.sqlite: is a SQLite file, not a crowdrecon run file"
                    export results/sweeps/madrid-arena/hallway-gamma/results.sqlite -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.damaged_run fail "fps-not-a-number.sqlite: table metadata, row key fps, column value: found"
                    export fuzz/regressions/fuzz_run_file/fps-not-a-number.sqlite -o @TMP@/x.sqlite)
crowdrecon_cli_test(export.output_folder_missing fail "no-such-folder/x.sqlite: .*no-such-folder does not exist. expected an existing folder"
                    export ${render_data}/run.sqlite -o @TMP@/no-such-folder/x.sqlite)
crowdrecon_cli_test(export.output_is_input fail "-o .*run.sqlite: is the run file .*an input is never overwritten, not even with --force"
                    export ${render_data}/run.sqlite -o ${render_data}/run.sqlite --force)
set_tests_properties(cli.export.periodic_run cli.export.empty_run cli.export.output_folder_missing
                     cli.export.output_is_input PROPERTIES FIXTURES_REQUIRED render_data)

# Observations (issue 22): bad inputs named with what was expected.
set(observe_data ${PROJECT_SOURCE_DIR}/tests/data/observe)
set(hallway_spec ${PROJECT_SOURCE_DIR}/venues/madrid-arena/observations/hallway.json)
set(bi_spec ${PROJECT_SOURCE_DIR}/venues/juelich/bidirectional-corridor.json)
crowdrecon_cli_test(observe.spec_without_regions fail "spec-no-regions.json: /regions: expected a list of at least one region"
                    observe trajectories ${observe_data}/not-petrack.txt --spec ${observe_data}/spec-no-regions.json -o @TMP@/o.json)
crowdrecon_cli_test(observe.not_petrack fail "not-petrack.txt:2: .*3 fields. expected id frame x y \\[z\\]"
                    observe trajectories ${observe_data}/not-petrack.txt --spec ${bi_spec} -o @TMP@/o.json)
crowdrecon_cli_test(observe.output_not_json fail "-o .*o.txt: expected a file name ending in .json"
                    observe trajectories ${observe_data}/not-petrack.txt --spec ${bi_spec} -o @TMP@/o.txt)
crowdrecon_cli_test(observe.output_is_input fail "is the trajectories .*an input is never overwritten"
                    observe trajectories ${bi_spec} --spec ${bi_spec} -o ${bi_spec} --force)
crowdrecon_cli_test(observe.not_a_video fail "README.md: cannot be read as a video"
                    observe footage README.md --homography ${observe_data}/far-away.json --spec ${hallway_spec} -o @TMP@/o.json)
crowdrecon_cli_test(observe.three_pairs fail "three-pairs.json: 3 point pairs. expected at least 4 image <-> floor pairs"
                    observe footage README.md --homography ${observe_data}/three-pairs.json --spec ${hallway_spec} -o @TMP@/o.json)
crowdrecon_cli_test(observe.collinear_pairs fail "collinear.json: the floor points lie on one line"
                    observe footage README.md --homography ${observe_data}/collinear.json --spec ${hallway_spec} -o @TMP@/o.json)
crowdrecon_cli_test(observe.singular_matrix fail "singular.json: the homography matrix is singular"
                    observe footage README.md --homography ${observe_data}/singular.json --spec ${hallway_spec} -o @TMP@/o.json)
crowdrecon_cli_test(observe.fd_spec_count fail "--spec: 2 given for 3 files. expected one for all or one per file"
                    observe fd a.txt b.txt c.txt --spec ${bi_spec} --spec ${bi_spec} -o @TMP@/fd.png)
crowdrecon_cli_test(observe.synthesize_not_a_run fail "README.md: .*not a crowdrecon run file"
                    observe synthesize README.md -o @TMP@/v.avi --homography-out @TMP@/h.json)
crowdrecon_cli_test(observe.compare_not_an_observation fail "hallway.json: /format: .*expected \"crowdrecon-observation\""
                    observe compare ${hallway_spec} ${hallway_spec})

# Calibration files (issue 23): refused with the file, the JSON path, the
# value and what was expected; an output folder that is not a calibration's.
set(calibration_data ${PROJECT_SOURCE_DIR}/tests/data/calibration)
crowdrecon_cli_test(calibrate.not_json fail "README.md:1:1: .*JSON"
                    calibrate README.md -o @TMP@/c)
crowdrecon_cli_test(calibrate.unknown_parameter fail "bad-parameter.json: /parameters/0/path: \"model.back_force_gama\" is not a model parameter"
                    calibrate ${calibration_data}/bad-parameter.json -o @TMP@/c)
crowdrecon_cli_test(calibrate.missing_observation fail "bad-observation.json: /observations/0/file: cannot use the observation: .*nowhere.observation.json"
                    calibrate ${calibration_data}/bad-observation.json -o @TMP@/c)
crowdrecon_cli_test(calibrate.output_is_a_foreign_folder fail "-o .*calibration: exists and is a folder .*not a calibration folder"
                    calibrate ${calibration_data}/bad-parameter.json -o ${calibration_data})

# --- numbers: NaN and infinity are refused by every numeric option (issue 40) ---
crowdrecon_cli_test(timeline.smooth_nan fail "--smooth: value nan is not finite. expected a number in \\[0, 3600\\] s"
                    timeline README.md -o @TMP@/t.png --smooth nan)
crowdrecon_cli_test(timeline.tolerance_inf fail "--tolerance: value inf is not finite"
                    timeline README.md -o @TMP@/t.png --tolerance inf)
crowdrecon_cli_test(observe.compare_match_nan fail "--match: value nan is not finite"
                    observe compare a.json b.json --match nan)
crowdrecon_cli_test(observe.footage_to_nan fail "--to: value nan is not finite"
                    observe footage v.mp4 --homography h.json --spec s.json -o o.json --to nan)
crowdrecon_cli_test(report.envelope_level_nan fail "--envelope-level: value nan is not finite"
                    report README.md -o @TMP@/r --envelope-level nan)
crowdrecon_cli_test(observe.synthesize_negative_seed fail "--seed: value -1 is out of range. expected a whole number in \\[0, 4611686018427387904\\]"
                    observe synthesize run.sqlite -o @TMP@/v.avi --homography-out @TMP@/h.json --seed -1)
crowdrecon_cli_test(report.negative_table_rows fail "--table-rows: value -1 is out of range. expected a whole number in \\[0, 1000000\\]"
                    report README.md -o @TMP@/r --table-rows -1)
