# Sourced by the run tests: dump FILE prints a hash of every table a run writes
# per frame, in a fixed order (runs are compared byte for byte with it).
dump() {
  for q in "SELECT * FROM trajectory_data ORDER BY frame, id" \
           "SELECT * FROM person_state ORDER BY frame, id" \
           "SELECT * FROM contact ORDER BY frame, rowid" \
           "SELECT * FROM frame_time ORDER BY frame"; do
    sqlite3 -separator ' ' "$1" ".mode quote" "$q"
  done | sha256sum | cut -d' ' -f1
}
