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
# dump_all FILE: the same with the events, the chest loads (table person_load)
# and a timeline's head count (table census) where the run has one: what a
# resumed run must reproduce besides the frames.
dump_all() {
  local census="SELECT 'no census'"
  if [[ $(sqlite3 "$1" "SELECT COUNT(*) FROM sqlite_master WHERE name = 'census'") == 1 ]]; then
    census="SELECT * FROM census ORDER BY frame"
  fi
  { dump "$1"
    sqlite3 -separator ' ' "$1" ".mode quote" "SELECT * FROM event ORDER BY frame, rowid"
    sqlite3 -separator ' ' "$1" ".mode quote" "SELECT * FROM person_load ORDER BY frame, id"
    sqlite3 -separator ' ' "$1" ".mode quote" "$census"; } | sha256sum | cut -d' ' -f1
}
# last_frame FILE: the last frame a run being written has committed, 0 while
# there is none. It reads only: a plain `sqlite3 FILE` creates FILE when it is
# not there yet, and a poll that lands while simulate is creating its file
# broke simulate's switch to write-ahead logging ("disk I/O error", CI of
# stop 51); so no file means 0, and an existing one is opened read-only.
last_frame() {
  [[ -s $1 ]] || { echo 0; return; }
  sqlite3 -readonly "$1" "SELECT COALESCE(MAX(frame),0) FROM frame_time" 2>/dev/null || echo 0
}
