# Outputs never destroy anything (common/output_path.hpp, README "Outputs"):
# for every command that writes, an output that names an input, a folder or a
# file that is not a previous output of the same kind is refused, and the
# scratch folder (".") or the named paths are checked unchanged afterwards
# (expect_unchanged.sh); previous outputs of the same kind are replaced.
#   crowdrecon_output_test(NAME ok|fail REGEX SETUP KEEP ARGS...)
set(CLI_UNCHANGED ${CMAKE_CURRENT_SOURCE_DIR}/cli/expect_unchanged.sh)
function(crowdrecon_output_test name status regex setup keep)
  add_test(NAME cli.outputs.${name}
           COMMAND bash ${CLI_UNCHANGED} ${status} ${regex} "${setup}" "${keep}" -- ${CROWDRECON_EXE} ${ARGN}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endfunction()
set(INPUTS "scenario.json venue.json body.json")
set(ANSUR ${PROJECT_SOURCE_DIR}/venues/bodies/ansur2-thorax.csv)
set(OUTLINE "cp $SRC/venues/bodies/thorax-reference.json outline.json")
set(NOT_EVEN_FORCE "an input is never overwritten, not even with --force")
set(NO_FOLDER "a folder is never replaced by a file")

# --- simulate ------------------------------------------------------------------
crowdrecon_output_test(simulate.o_is_scenario fail "-o scenario.json: is the scenario \\(scenario.json\\), an input of this command. ${NOT_EVEN_FORCE}"
                       make_scenario . simulate scenario.json -o scenario.json -q)
# Issue 65: a file name ending with a separator names a folder (it wrote a run file "x" and failed later).
crowdrecon_output_test(simulate.o_names_a_folder fail "-o x/: names a folder, not a crowdrecon run file. give a file name"
                       make_scenario . simulate scenario.json -o x/ -q)
crowdrecon_output_test(simulate.o_is_venue fail "-o venue.json: is the venue \\(.*venue.json\\)"
                       make_scenario . simulate scenario.json -o venue.json -q)
crowdrecon_output_test(simulate.o_is_body fail "-o body.json: is the reference body \\(.*body.json\\)"
                       make_scenario . simulate scenario.json -o body.json -q)
crowdrecon_output_test(simulate.o_is_scenario_through_symlink fail "-o link.sqlite: is the scenario"
                       "make_scenario && ln -s scenario.json link.sqlite" . simulate scenario.json -o link.sqlite -q)
crowdrecon_output_test(simulate.o_is_scenario_through_hard_link fail "-o hard.sqlite: is the scenario"
                       "make_scenario && ln scenario.json hard.sqlite" . simulate scenario.json -o hard.sqlite -q)
crowdrecon_output_test(simulate.force_cannot_overwrite_scenario fail "-o scenario.json: is the scenario.*${NOT_EVEN_FORCE}"
                       make_scenario . simulate scenario.json -o scenario.json -q --force)
crowdrecon_output_test(simulate.o_empty_folder fail "-o out: exists and is an empty folder, not a crowdrecon run file. ${NO_FOLDER}"
                       "make_scenario && mkdir out" . simulate scenario.json -o out -q)
crowdrecon_output_test(simulate.o_folder_with_file fail "-o out: exists and is a folder holding 1 entry \\(notes.txt\\), not a crowdrecon run file. ${NO_FOLDER}"
                       "make_scenario && mkdir out && foreign out/notes.txt" . simulate scenario.json -o out -q --force)
crowdrecon_output_test(simulate.o_foreign_json fail "-o other.json: exists and is a JSON file, not a crowdrecon run file. choose another name or --force"
                       "make_scenario && cp venue.json other.json" . simulate scenario.json -o other.json -q)
crowdrecon_output_test(simulate.o_foreign_text fail "-o run.sqlite: exists and is a text file of [0-9]+ bytes, not a crowdrecon run file"
                       "make_scenario && foreign run.sqlite" . simulate scenario.json -o run.sqlite -q)
crowdrecon_output_test(simulate.resume_foreign_file fail "run.sqlite: nothing to resume: it is a text file of [0-9]+ bytes, not a crowdrecon run file"
                       "make_scenario && foreign run.sqlite" . simulate scenario.json -o run.sqlite -q --resume)
crowdrecon_output_test(simulate.o_previous_run_replaced ok "run file: run.sqlite \\(3 frames\\), status complete"
                       "make_scenario && make_run" ${INPUTS} simulate scenario.json -o run.sqlite -q)
crowdrecon_output_test(simulate.force_replaces_foreign_file ok "run file: run.sqlite \\(3 frames\\), status complete"
                       "make_scenario && foreign run.sqlite" ${INPUTS} simulate scenario.json -o run.sqlite -q --force)

# --- shape, population, body reference -----------------------------------------
crowdrecon_output_test(shape.o_is_outline fail "-o outline.json: is the outline \\(outline.json\\)"
                       ${OUTLINE} . shape outline.json -o outline.json --front +x)
crowdrecon_output_test(shape.picture_is_outline_image fail "--picture e.png: is the outline \\(e.png\\)"
                       "cp $SRC/tests/data/bodies/ellipse-1000ppm.png e.png" . shape e.png -o b.json --picture e.png)
crowdrecon_output_test(shape.o_and_picture_same_path fail "-o and --picture both name b.json. give each output its own name"
                       ${OUTLINE} . shape outline.json -o b.json --picture b.json)
crowdrecon_output_test(shape.o_foreign_file fail "-o b.json: exists and is a text file of [0-9]+ bytes, not a body JSON \\(format crowdrecon-body\\). choose another name or --force"
                       "${OUTLINE} && foreign b.json" . shape outline.json -o b.json)
crowdrecon_output_test(shape.o_empty_folder fail "-o b: exists and is an empty folder, not a body JSON.*${NO_FOLDER}"
                       "${OUTLINE} && mkdir b" . shape outline.json -o b --force)
crowdrecon_output_test(shape.o_previous_body_replaced ok "wrote b.json"
                       "${OUTLINE} && cp $SRC/venues/bodies/thorax-18.json b.json" outline.json shape outline.json -o b.json --front +x)
crowdrecon_output_test(shape.force_replaces_foreign_file ok "wrote b.json"
                       "${OUTLINE} && foreign b.json" outline.json shape outline.json -o b.json --front +x --force)
crowdrecon_output_test(population.o_is_body fail "-o body.json: is the reference body \\(body.json\\)"
                       "cp $SRC/venues/bodies/thorax-18.json body.json" . population --body body.json -o body.json --count 5)
crowdrecon_output_test(population.force_cannot_overwrite_body fail "-o body.json: is the reference body.*${NOT_EVEN_FORCE}"
                       "cp $SRC/venues/bodies/thorax-18.json body.json" . population --body body.json -o body.json --count 5 --force)
crowdrecon_output_test(population.o_is_anthropometry fail "-o a.csv: is the anthropometry extract \\(a.csv\\)"
                       "cp ${ANSUR} a.csv" . population --mode anthropometric --anthropometry a.csv -o a.csv --count 5 --force)
crowdrecon_output_test(population.o_folder_with_file fail "-o p: exists and is a folder holding 1 entry \\(notes.txt\\), not a population JSON"
                       "mkdir p && foreign p/notes.txt" . population --body ${PROJECT_SOURCE_DIR}/venues/bodies/thorax-18.json -o p --count 5)
crowdrecon_output_test(population.picture_foreign_file fail "--picture pic.png: exists and is a text file of [0-9]+ bytes, not a picture \\(PNG, SVG or PDF\\)"
                       "foreign pic.png" . population --body ${PROJECT_SOURCE_DIR}/venues/bodies/thorax-18.json -o p.json --count 5 --picture pic.png)
crowdrecon_output_test(population.o_previous_population_replaced ok "wrote p.json"
                       "$EXE population --body $SRC/venues/bodies/thorax-18.json -o p.json --count 3 >/dev/null" ""
                       population --body ${PROJECT_SOURCE_DIR}/venues/bodies/thorax-18.json -o p.json --count 5)
crowdrecon_output_test(body_reference.o_is_anthropometry fail "-o a.csv: is the anthropometry extract"
                       "cp ${ANSUR} a.csv" . body reference --anthropometry a.csv --outline o.json -o a.csv)
crowdrecon_output_test(body_reference.outline_and_o_same_path fail "--outline and -o both name x.json"
                       true . body reference --anthropometry ${ANSUR} --outline x.json -o x.json)
crowdrecon_output_test(body_reference.outline_foreign_file fail "--outline o.json: exists and is a text file of [0-9]+ bytes, not an outline JSON"
                       "foreign o.json" . body reference --anthropometry ${ANSUR} --outline o.json -o b.json)
crowdrecon_output_test(body_reference.previous_outputs_replaced ok "wrote b.json"
                       "cp $SRC/venues/bodies/thorax-reference.json o.json && cp $SRC/venues/bodies/thorax-18.json b.json" ""
                       body reference --anthropometry ${ANSUR} --outline o.json -o b.json)

# --- venues ----------------------------------------------------------------------
crowdrecon_output_test(venue_import.o_is_floor_plan fail "-o room.wkt: is the floor plan \\(room.wkt\\)"
                       "cp $SRC/tests/data/venues/room.wkt room.wkt" . venue import room.wkt -o room.wkt --force)
crowdrecon_output_test(venue_import.o_empty_folder fail "-o v: exists and is an empty folder, not a venue JSON.*${NO_FOLDER}"
                       "cp $SRC/tests/data/venues/room.wkt room.wkt && mkdir v" . venue import room.wkt -o v)
crowdrecon_output_test(venue_import.o_foreign_json fail "-o v.json: exists and is a JSON file, not a venue JSON \\(version, walkable_area\\). choose another name or --force"
                       "cp $SRC/tests/data/venues/room.wkt room.wkt && cp $SRC/venues/bodies/thorax-18.json v.json" . venue import room.wkt -o v.json)
crowdrecon_output_test(venue_import.o_previous_venue_replaced ok "wrote v.json"
                       "cp $SRC/tests/data/venues/room.wkt room.wkt && cp $SRC/tests/data/venues/room.json v.json" room.wkt venue import room.wkt -o v.json)
crowdrecon_output_test(venue_import.force_replaces_foreign_file ok "wrote v.json"
                       "cp $SRC/tests/data/venues/room.wkt room.wkt && foreign v.json" room.wkt venue import room.wkt -o v.json --force)
crowdrecon_output_test(venue_check.picture_is_venue fail "--picture v.json: is the venue \\(v.json\\)"
                       "cp $SRC/tests/data/venues/room.json v.json" . venue check v.json --picture v.json --force)

# --- render, analyze ----------------------------------------------------------------
crowdrecon_output_test(render.o_is_run_file fail "-o run.sqlite: is the run file \\(run.sqlite\\)"
                       "make_scenario && make_run" . render run.sqlite -o run.sqlite)
crowdrecon_output_test(render.video_is_run_file_through_symlink fail "--video run.mp4: is the run file"
                       "make_scenario && make_run && ln -s run.sqlite run.mp4" . render run.sqlite -o frames --video run.mp4 --force)
crowdrecon_output_test(render.o_folder_with_file fail "-o frames: exists and is a folder holding 1 entry \\(notes.txt\\), not a frames folder.*--force \\(which writes into the folder and deletes nothing in it\\)"
                       "make_scenario && make_run && mkdir frames && foreign frames/notes.txt" . render run.sqlite -o frames --frames first)
crowdrecon_output_test(render.o_is_a_file fail "-o frames: exists and is a text file of [0-9]+ bytes, not a folder for a frames folder"
                       "make_scenario && make_run && foreign frames" . render run.sqlite -o frames --frames first --force)
crowdrecon_output_test(render.video_foreign_file fail "--video v.avi: exists and is a text file of [0-9]+ bytes, not a video \\(MP4 or AVI\\)"
                       "make_scenario && make_run && foreign v.avi" . render run.sqlite -o frames --frames first --video v.avi)
crowdrecon_output_test(render.o_empty_folder_written_into ok "rendered 1 frame"
                       "make_scenario && make_run && mkdir frames" run.sqlite render run.sqlite -o frames --frames first)
crowdrecon_output_test(render.o_previous_frames_written_into ok "rendered 1 frame"
                       "make_scenario && make_run && $EXE render run.sqlite -o frames --frames last >/dev/null" "run.sqlite frames/frame_000002.png"
                       render run.sqlite -o frames --frames first)
crowdrecon_output_test(render.force_keeps_foreign_files ok "rendered 1 frame"
                       "make_scenario && make_run && mkdir frames && foreign frames/notes.txt" "run.sqlite frames/notes.txt"
                       render run.sqlite -o frames --frames first --force)
crowdrecon_output_test(analyze.json_is_run_file fail "--json run.sqlite: is the run file \\(run.sqlite\\).*${NOT_EVEN_FORCE}"
                       "make_scenario && make_run" . analyze run.sqlite --json run.sqlite --force)
crowdrecon_output_test(analyze.json_foreign_json fail "--json a.json: exists and is a JSON file, not an analysis JSON"
                       "make_scenario && make_run && cp venue.json a.json" . analyze run.sqlite --json a.json)
crowdrecon_output_test(analyze.json_folder fail "--json a: exists and is an empty folder, not an analysis JSON.*${NO_FOLDER}"
                       "make_scenario && make_run && mkdir a" . analyze run.sqlite --json a --force)
crowdrecon_output_test(analyze.json_previous_replaced ok "json: a.json"
                       "make_scenario && make_run && $EXE analyze run.sqlite --json a.json >/dev/null" run.sqlite analyze run.sqlite --json a.json)

# --- export ------------------------------------------------------------------------
crowdrecon_output_test(export.o_is_run_file fail "-o run.sqlite: is the run file \\(run.sqlite\\), an input of this command. ${NOT_EVEN_FORCE}"
                       "make_scenario && make_run" . export run.sqlite -o run.sqlite --force)
crowdrecon_output_test(export.o_is_run_file_through_symlink fail "-o link.sqlite: is the run file"
                       "make_scenario && make_run && ln -s run.sqlite link.sqlite" . export run.sqlite -o link.sqlite)
crowdrecon_output_test(export.o_other_run fail "-o other.sqlite: exists and is a SQLite file, not a crowdrecon trajectory export. choose another name or --force"
                       "make_scenario && make_run && cp run.sqlite other.sqlite" . export run.sqlite -o other.sqlite)
crowdrecon_output_test(export.o_empty_folder fail "-o out: exists and is an empty folder, not a crowdrecon trajectory export. ${NO_FOLDER}"
                       "make_scenario && make_run && mkdir out" . export run.sqlite -o out --force)
crowdrecon_output_test(export.o_previous_export_replaced ok "wrote x.sqlite"
                       "make_scenario && make_run && $EXE export run.sqlite -o x.sqlite >/dev/null" run.sqlite export run.sqlite -o x.sqlite)
crowdrecon_output_test(export.force_replaces_foreign_file ok "wrote x.sqlite"
                       "make_scenario && make_run && foreign x.sqlite" run.sqlite export run.sqlite -o x.sqlite --force)
# A run found damaged while the export is written leaves nothing behind (no partial file).
crowdrecon_output_test(export.damaged_run_leaves_nothing fail "bad.sqlite: table metadata, row key fps"
                       "cp $SRC/fuzz/regressions/fuzz_run_file/fps-not-a-number.sqlite bad.sqlite" . export bad.sqlite -o x.sqlite)

# --- sweep, phase ------------------------------------------------------------------
crowdrecon_output_test(sweep.o_is_sweep_file fail "-o sweep.json: is the sweep file \\(sweep.json\\)"
                       make_sweep . sweep sweep.json -o sweep.json -q --force)
crowdrecon_output_test(sweep.o_folder_with_file fail "-o s: exists and is a folder holding 1 entry \\(notes.txt\\), not a sweep folder"
                       "make_sweep && mkdir s && foreign s/notes.txt" . sweep sweep.json -o s -q)
crowdrecon_output_test(sweep.o_foreign_results fail "-o s: exists and is a folder holding 1 entry \\(results.sqlite\\), not a sweep folder"
                       "make_sweep && mkdir s && foreign s/results.sqlite" . sweep sweep.json -o s -q)
crowdrecon_output_test(sweep.o_is_a_file fail "-o s: exists and is a text file of [0-9]+ bytes, not a folder for a sweep folder"
                       "make_sweep && foreign s" . sweep sweep.json -o s -q --force)
crowdrecon_output_test(phase.o_is_sweep_folder fail "-o sw: is the sweep results \\(sw\\)"
                       "mkdir sw && foreign sw/results.sqlite" . phase sw -o sw --force)
crowdrecon_output_test(phase.o_folder_with_file fail "-o fig: exists and is a folder holding 1 entry \\(notes.txt\\), not a phase folder"
                       "mkdir fig && foreign fig/notes.txt" . phase ${CMAKE_CURRENT_BINARY_DIR}/out/sweep/j1 -o fig)
crowdrecon_output_test(phase.o_previous_phase_folder_written_into ok "drew 2 phase diagram"
                       "$EXE phase ${CMAKE_CURRENT_BINARY_DIR}/out/sweep/j1 -o fig --no-heat-maps >/dev/null" ""
                       phase ${CMAKE_CURRENT_BINARY_DIR}/out/sweep/j1 -o fig --no-heat-maps)
set_tests_properties(cli.outputs.phase.o_previous_phase_folder_written_into PROPERTIES FIXTURES_REQUIRED sweep_tiny)

# --- resume before the first checkpoint --------------------------------------------
add_test(NAME cli.outputs.resume_before_first_checkpoint
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/resume_before_checkpoint.sh ${CROWDRECON_EXE}
                 ${PROJECT_SOURCE_DIR}/tests/data/scenarios/hallway-short.json
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})

# --- observe: an observation read is an input, its series file too (issue 40) ---
crowdrecon_output_test(observe.compare_csv_is_the_references_series fail
                       "--csv ref.csv: is the reference's series \\(ref.csv\\), an input of this command. ${NOT_EVEN_FORCE}"
                       "make_scenario && make_run && make_observation" "ref.json ref.csv"
                       observe compare ref.json ref.json --csv ref.csv --force)
crowdrecon_output_test(observe.footage_o_writes_the_references_series fail
                       "-o \\(its series\\) .*ref.csv: is the reference's series"
                       "make_scenario && make_run && make_observation && mv ref.json renamed.json" "renamed.json ref.csv"
                       observe footage video.mp4 --homography h.json --spec s.json -o ref.json --reference renamed.json)

# --- validate: the report's folder never inside the suite (issue 65) ----------
crowdrecon_output_test(validate.o_inside_the_suite fail "-o suite/tests: inside the suite.s folder .*suite, whose files are read as its tests"
                       "mkdir -p suite/tests && echo {} > suite/tests/t.json" "."
                       validate suite -o suite/tests --force --no-pdf)

# --- every option checked before anything is written (issue 40) ----------------
crowdrecon_output_test(timeline.bad_density_time_writes_nothing fail
                       "--density-times / --density-cell / --density-sigma: time -1 s, expected a finite time in seconds at or after the start"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png --density-maps d.png --density-times -1)
crowdrecon_output_test(timeline.scores_and_density_maps_of_one_run fail
                       "--density-maps draws one run.s maps: with --scores the run is scored as an ensemble \\(of one\\). draw it in a call without --scores"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png --scores s.md --density-maps d.png)
crowdrecon_output_test(timeline.density_time_not_finite fail
                       "--density-times / --density-cell / --density-sigma: time inf, expected a finite time in seconds"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png --density-maps d.png --density-times inf)
crowdrecon_output_test(timeline.density_time_after_the_end_writes_nothing fail
                       "density map time 99 s lies after the run.s end \\(.* s\\). expected times within the run"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png --density-maps d.png --density-times 0,99)
crowdrecon_output_test(timeline.bad_second_extension_writes_nothing fail
                       "-o t.bmp: unknown picture format .*bmp.*expected .png, .svg or .pdf"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png -o t.bmp)
crowdrecon_output_test(timeline.bad_phase_folder_writes_nothing fail
                       "nowhere"
                       "make_scenario && make_run" "."
                       timeline run.sqlite -o t.png --phase nowhere)

# --- an output folder that cannot be made is an answer, not an internal error (issue 40) ---
set(LONG_NAME "nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn")
crowdrecon_output_test(report.folder_name_too_long fail
                       "cannot create the output folder: File name too long"
                       "make_scenario && make_run" "."
                       report run.sqlite -o ${LONG_NAME} --no-pdf)
crowdrecon_output_test(calibrate.folder_name_too_long fail
                       "cannot create the output folder: File name too long"
                       "true" "."
                       calibrate ${PROJECT_SOURCE_DIR}/venues/madrid-arena/calibrations/madrid-night-demo.json -o ${LONG_NAME})
crowdrecon_output_test(report.same_run_twice fail
                       "run.sqlite: given twice .also as run.sqlite.. each run counts once"
                       "make_scenario && make_run" "."
                       report run.sqlite run.sqlite -o r --no-pdf)
