# Geometry inputs (body outlines, body files, pictures, WKT, DXF, raster plans)
# never crash, hang or run out of memory: each case checks the exit status
# (2 for a user error), the message (file, place, value, what was expected),
# the processor time it took (not the wall time: geometry_case.sh says why),
# and that nothing was written. Large inputs are made by the test
# (cli/make_geometry_input.py) at a size that took more than 10 s before the
# fix, or just over a limit of crowdrecon/geometry/input_limits.hpp.
set(GEOMETRY_CASE ${CMAKE_CURRENT_SOURCE_DIR}/cli/geometry_case.sh)
# geometry_case(NAME INPUT STATUS REGEX SECONDS crowdrecon-arguments...)
function(geometry_case name input status regex seconds)
  # The time limits are those of the release build (near-linear work); the
  # sanitizer build runs the same code 5 to 15 times slower, so there they
  # only guard against a hang.
  if(CROWDRECON_SANITIZE)
    math(EXPR seconds "${seconds} * 6")
  endif()
  add_test(NAME cli.bad_geometry.${name}
           COMMAND bash ${GEOMETRY_CASE} "${input}" ${status} "${regex}" ${seconds} -- $<TARGET_FILE:crowdrecon> ${ARGN}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(cli.bad_geometry.${name} PROPERTIES ENVIRONMENT "PYTHON=${Python3_EXECUTABLE}")
endfunction()
set(B tests/data/bodies)
set(V tests/data/venues)

# 1. Coordinates no body outline can have (1e154: SIGSEGV before).
geometry_case(huge_coordinate_json none fail
  "huge-coordinates.json: /1: coordinate 1e\\+154 is beyond 1000000000 in magnitude.*check the scale/units" 10
  shape ${B}/huge-coordinates.json -o @TMP@/out.json)
geometry_case(huge_coordinate_csv none fail
  "huge-coordinates.csv:4: coordinate 1e\\+200 is beyond 1000000000" 10 shape ${B}/huge-coordinates.csv -o @TMP@/out.json)
geometry_case(nan_csv none fail "nan.csv:3: coordinate nan is not finite; expected finite x, y" 10
  shape ${B}/nan.csv -o @TMP@/out.json)
geometry_case(huge_body_file none fail
  "far-body.json: /vertices_m/0: coordinate -1e\\+154 m is beyond 3 m from the centroid.*check the units" 10
  population --mode paper --body ${B}/far-body.json --count 2 -o @TMP@/out.json)

# 2. Pictures: a 3000 x 3000 dark square took 34 s (the simplification was
# cubic in the collinear border pixels); above 100 megapixels is refused from
# the header; OpenCV's own limit is an input error naming the file.
geometry_case(dark_picture_3000px "png 3000 3000 dark.png" ok "vertices: 4, sphero-radius 0.05 m" 10
  shape @TMP@/dark.png -o @TMP@/body.json)
geometry_case(picture_over_pixel_limit "png-header 20000 20000 big.png" fail
  "big.png: the picture is 20000 x 20000 pixels \\(400 megapixels\\); at most 100 megapixels are accepted: check the resolution" 10
  shape @TMP@/big.png -o @TMP@/out.json)
geometry_case(plan_over_pixel_limit "png-header 12000 9000 plan.png" fail
  "plan.png: the picture is 12000 x 9000 pixels \\(108 megapixels\\); at most 100 megapixels" 10
  venue import @TMP@/plan.png --pixels-per-metre 50 -o @TMP@/out.json)
geometry_case(netpbm_over_pixel_limit "pgm-header 50000 50000 big.pgm" fail
  "big.pgm: the picture is 50000 x 50000 pixels \\(2500 megapixels\\)" 10
  shape @TMP@/big.pgm -o @TMP@/out.json)
add_test(NAME cli.bad_geometry.opencv_pixel_limit
         COMMAND bash ${GEOMETRY_CASE} none fail
                 "ellipse-1000ppm.png: OpenCV cannot decode the picture \\(.*\\); expected a picture of at most 100 megapixels" 10
                 -- env OPENCV_IO_MAX_IMAGE_PIXELS=1000 $<TARGET_FILE:crowdrecon>
                 shape ${B}/ellipse-1000ppm.png --scale ppm:1000 -o @TMP@/out.json
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})

# 3. Outlines in the wrong units (a 10 m square: 14.5 s; 1e4 m: 3.4 GB before).
geometry_case(outline_10m "square 10 square.json" fail
  "square.json: the outline is 10 m across \\(scale none, 1 m per unit\\); a body is 0.2-1 m across and at most 3 m is accepted: check the scale/units" 10
  shape @TMP@/square.json -o @TMP@/out.json)
geometry_case(outline_1e4m "square 10000 square.json" fail "square.json: the outline is 10000 m across" 10
  shape @TMP@/square.json -o @TMP@/out.json)
geometry_case(outline_pixels_at_wrong_ppm "png 3000 3000 dark.png" fail
  "dark.png: the outline is 29.9. m across \\(scale ppm:100, 0.01 m per pixel\\)" 10
  shape @TMP@/dark.png --scale ppm:100 -o @TMP@/out.json)
# Just under the limit, densely given: the Hausdorff sampling is near-linear.
geometry_case(outline_2_9m_dense "square 2.9 20000 square.json" ok "Hausdorff distance outline - swept shape" 10
  shape @TMP@/square.json -o @TMP@/body.json)

# 4. DXF arrays: MINSERT of 100000 x 100000 copies took 31 s and 7.7 GB, then
# "internal error: std::bad_alloc".
geometry_case(dxf_minsert_huge "minsert 100000 100000 plan.dxf" fail
  "plan.dxf:[0-9]+: the INSERT of block \"PILLAR\" \\(100000 x 100000 copies\\) expands to 1e\\+10 entities.*at most 20000 entities" 10
  venue import @TMP@/plan.dxf -o @TMP@/out.json)
geometry_case(dxf_minsert_over_limit "minsert 150 150 plan.dxf" fail "plan.dxf:[0-9]+: the INSERT of block \"PILLAR\" \\(150 x 150 copies\\) expands to 22500 entities.*at most 20000 entities" 10
  venue import @TMP@/plan.dxf -o @TMP@/out.json)
geometry_case(dxf_minsert_under_limit "minsert 100 100 plan.dxf" ok "10000 obstacle\\(s\\)" 20
  venue import @TMP@/plan.dxf -o @TMP@/out.json)
geometry_case(dxf_too_many_points none fail
  "many-points.dxf:39: the INSERT of block \"C\" \\(20 x 20 copies\\) expands to 400 entities with 2513600 points.*at most 20000 entities and 1000000 points" 10
  venue import ${V}/many-points.dxf -o @TMP@/out.json)
geometry_case(dxf_too_many_curve_points "circles 200 plan.dxf" fail
  "plan.dxf: the drawing holds more than 1000000 points once its curves are flattened.*check the drawing's unit" 10
  venue import @TMP@/plan.dxf -o @TMP@/out.json)

# 5. Non-finite and out-of-range numbers in WKT, with line and column.
geometry_case(wkt_nan none fail "bad-nan.wkt:2:6: invalid WKT: the number nan is not finite; expected a finite coordinate" 10
  venue import ${V}/bad-nan.wkt -o @TMP@/out.json)
geometry_case(wkt_inf none fail "bad-inf.wkt:1:31: invalid WKT: the number inf is not finite" 10
  venue import ${V}/bad-inf.wkt -o @TMP@/out.json)
geometry_case(wkt_1e400 none fail "bad-1e400.wkt:1:16: invalid WKT: the number 1e400 is out of range" 10
  venue import ${V}/bad-1e400.wkt -o @TMP@/out.json)

# A self-intersecting outline of 400000 points: the edges that cross are
# found by a sweep (every pair of edges before: 8e10 tests).
geometry_case(bowtie_outline_400k "bowtie 0.5 100000 bowtie.json" fail
  "bowtie.json: the outline intersects itself \\(edge [0-9]+ .* crosses edge [0-9]+ .*\\); expected a simple closed outline" 10
  shape @TMP@/bowtie.json -o @TMP@/out.json)

# 6. A bow-tie body file is a self-intersection, not "all vertices collinear".
geometry_case(bowtie_body_file none fail "bowtie-body.json: /vertices_m: edges 0 .* and 2 .* intersect; the polygon must be simple" 10
  population --mode paper --body ${B}/bowtie-body.json --count 2 -o @TMP@/out.json)

# 7. Import validates as `venue check` does, before writing anything.
geometry_case(wkt_1e300 none fail
  "bad-1e300.wkt: /walkable_area/0/1: coordinate \\(1e\\+300, 0\\) is beyond 10000000 m; expected metres: check the scale/units" 10
  venue import ${V}/bad-1e300.wkt -o @TMP@/out.json)
# (--scale itself stops at 1e9 m per unit: the plan's 1e4 units become 1e13 m.)
geometry_case(dxf_scale_1e9 none fail "room.dxf: /walkable_area/0/1: coordinate \\(1e\\+13, 0\\) is beyond 10000000 m" 10
  venue import ${V}/room.dxf --scale 1e9 -o @TMP@/out.json)
# 150 circles 3e5 m apart: 232 problems (116 rings and their walls beyond 1e7 m), the first 20 shown.
geometry_case(dxf_many_problems_shortened "circles 150 plan.dxf" fail
  "\\(and 212 more problems of the same venue\\)" 10
  venue import @TMP@/plan.dxf -o @TMP@/out.json)
geometry_case(check_huge_coordinate none fail
  "bad-huge-coordinate.json: /measurement_lines/0/segment/1: coordinate \\(9, 1e\\+300\\) is beyond 10000000 m" 10
  venue check ${V}/bad-huge-coordinate.json)

# 8. A folder given as a picture, WKT, DXF, raster plan or point list.
geometry_case(directory_picture "dir outline.png" fail "outline.png: is a directory; expected a picture file" 10
  shape @TMP@/outline.png -o @TMP@/out.json)
geometry_case(directory_csv "dir outline.csv" fail "outline.csv: is a directory; expected a point list \\(CSV\\)" 10
  shape @TMP@/outline.csv -o @TMP@/out.json)
geometry_case(directory_wkt "dir plan.wkt" fail "plan.wkt: is a directory; expected a WKT file" 10
  venue import @TMP@/plan.wkt -o @TMP@/out.json)
geometry_case(directory_dxf "dir plan.dxf" fail "plan.dxf: is a directory; expected a DXF file" 10
  venue import @TMP@/plan.dxf -o @TMP@/out.json)
geometry_case(directory_plan "dir plan.png" fail "plan.png: is a directory; expected a picture file" 10
  venue import @TMP@/plan.png --pixels-per-metre 50 -o @TMP@/out.json)

# The picture and video codecs are a module loaded on first use
# (media/CMakeLists.txt); when it cannot be loaded, the command says which
# file and how to mend it, and writes nothing.
geometry_case(codecs_module_missing "png 40 40 dark.png" fail
  "cannot load the picture and video codecs \\(/nonexistent/codecs.so\\): .*set CROWDRECON_MEDIA_CODECS" 10
  shape @TMP@/dark.png -o @TMP@/out.json)
set_tests_properties(cli.bad_geometry.codecs_module_missing PROPERTIES
  ENVIRONMENT "PYTHON=${Python3_EXECUTABLE};CROWDRECON_MEDIA_CODECS=/nonexistent/codecs.so")
