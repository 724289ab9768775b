# Command-line tests of what fuzzing found (docs/fuzzing.md): each input
# crashed the program before its fix. The fuzz.replay.* tests (fuzz/CMakeLists.txt)
# replay every reproducer through its harness as well.

# A 135-byte file with "DICM" at byte 128: OpenCV handed it to GDCM, whose
# assertion aborted the program (SIGABRT) in `venue import` and `shape`.
crowdrecon_cli_test(fuzz.dicom_image_venue_import fail "^crowdrecon: error: .*bad-dicom.png: a DICOM .*expected a picture"
                    venue import tests/data/venues/bad-dicom.png --pixels-per-metre 50 -o @TMP@/v.json)
crowdrecon_cli_test(fuzz.dicom_image_shape fail "^crowdrecon: error: .*bad-dicom.png: a DICOM .*expected a picture"
                    shape tests/data/venues/bad-dicom.png -o @TMP@/b.json)
