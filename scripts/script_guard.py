"""What the scripts a user runs share with crowdrecon's own commands (issue 65):
their outputs never destroy anything, and a bad argument is answered with one
line that says what is wrong, not with a traceback.

The output rules are the binary's (common/include/crowdrecon/common/output_path.hpp):

  - an input is never an output: compared by what the paths name (the same
    file also through symbolic and hard links; a path not yet written by its
    resolved, normalised name), not even with --force;
  - a folder is never replaced by a file, and nothing in a folder is deleted;
  - an existing path that is a previous output of the same kind is replaced
    (files) or written into (folders): that is how a script is run again; so
    is an empty file or an empty folder, which holds nothing to lose;
  - anything else that exists is refused with a message saying what is
    there, unless --force is given (a file is then replaced; a folder is
    written into, and what it holds is left alone);
  - two outputs never name the same path;
  - files are written whole: under a temporary name in the same folder, then
    renamed over the output (os.replace), so that an error, Ctrl-C or a kill
    never leaves a partial, complete-looking file (the previous output, if
    any, stays as it was until the rename).

A script's output folder (OUT_DIR of the studies) is a folder kind whose
previous output is a folder already holding one of the script's own files
(`folder_with`), or only its own entries (`folder_of`, for folders that the
script empties itself); each file written into it is checked as well.

Errors: `ScriptError(message)` anywhere below `run_main`, or `fail(message)`,
print one line "SCRIPT: error: WHAT: PROBLEM; expected ..." on stderr and exit
with status 2, before anything is written. `ArgumentParser` answers argparse's
own errors (a missing or unknown argument, a value its `type=` refuses) the
same way; the validators below are for `type=`.

Standard library only. The scripts in this folder import it directly (they
run as files, so this folder is on the path); the studies' scripts put
<repo>/scripts on the path first, as they do for svg_png and ensemble_stats.
"""
import argparse
import contextlib
import csv
import fnmatch
import json
import math
import os
import pathlib
import re
import shutil
import signal
import sqlite3
import sys
import threading

SQLITE_MAGIC = b"SQLite format 3\x00"
EXIT_BAD_INPUT = 2


# ---------------------------------------------------------------- errors

class ScriptError(Exception):
    """A bad input or argument: the message is one line, "WHAT: PROBLEM; expected ..."."""


def prog():
    """The script's name for messages (its file name, as argparse says it)."""
    return os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "script"


def one_line(text):
    return " ".join(str(text).split())


def fail(message, status=EXIT_BAD_INPUT):
    """Prints "SCRIPT: error: MESSAGE" (one line) on stderr and exits with `status` (2: bad input)."""
    sys.stderr.write(f"{prog()}: error: {one_line(message)}\n")
    sys.stderr.flush()
    sys.exit(status)


def run_main(main, *args):
    """Calls main(*args); a ScriptError raised anywhere in it becomes fail(). Exits with what main returns."""
    try:
        result = main(*args)
    except ScriptError as e:
        fail(str(e))
    sys.exit(result if isinstance(result, int) else 0)


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser whose errors are one line and exit 2:
    "SCRIPT: error: argument --scale: 0 is not above 0; expected a positive number"."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {one_line(message)} (see --help)\n")


def add_force(parser):
    parser.add_argument("--force", action="store_true",
                        help="replace an existing file that is not a previous output of this script, or write into "
                             "such a folder (nothing in it is deleted); an input is never overwritten")


# ---------------------------------------------------------------- validators for argparse's type=

def _type_error(text):
    return argparse.ArgumentTypeError(text)


def _named(fn, name):
    fn.__name__ = name
    return fn


def _int(text, expected):
    try:
        return int(str(text).strip())
    except ValueError:
        raise _type_error(f"{text!r} is not a whole number; expected {expected}") from None


def _float(text, expected):
    try:
        value = float(str(text).strip())
    except ValueError:
        raise _type_error(f"{text!r} is not a number; expected {expected}") from None
    if not math.isfinite(value):
        raise _type_error(f"{text!r} is not a finite number; expected {expected}")
    return value


def int_between(low=None, high=None, what=None):
    """A whole number in [low, high] (None: unbounded)."""
    if low is not None and high is not None:
        expected = f"a whole number from {low} to {high}"
    elif low is not None:
        expected = f"a whole number of at least {low}"
    elif high is not None:
        expected = f"a whole number of at most {high}"
    else:
        expected = "a whole number"
    if what:
        expected += f" ({what})"

    def check(text):
        value = _int(text, expected)
        if (low is not None and value < low) or (high is not None and value > high):
            raise _type_error(f"{value} is out of range; expected {expected}")
        return value
    return _named(check, "int_between")


def positive_int(text):
    return int_between(1)(text)


def nonnegative_int(text):
    return int_between(0)(text)


def float_between(low=None, high=None, low_open=False, high_open=False, what=None):
    """A finite number in the interval (open ends where asked; None: unbounded)."""
    parts = []
    if low is not None:
        parts.append(f"{'above' if low_open else 'at least'} {low:g}")
    if high is not None:
        parts.append(f"{'below' if high_open else 'at most'} {high:g}")
    expected = "a number" + (" " + " and ".join(parts) if parts else "") + (f" ({what})" if what else "")

    def check(text):
        value = _float(text, expected)
        if low is not None and (value < low or (low_open and value == low)):
            raise _type_error(f"{text} is out of range; expected {expected}")
        if high is not None and (value > high or (high_open and value == high)):
            raise _type_error(f"{text} is out of range; expected {expected}")
        return value
    return _named(check, "float_between")


def finite_float(text):
    return float_between()(text)


def positive_float(text):
    return float_between(0.0, low_open=True)(text)


def nonnegative_float(text):
    return float_between(0.0)(text)


def fraction(text):
    return float_between(0.0, 1.0)(text)


def float_list(text, item=finite_float):
    """Comma-separated numbers, each checked by `item`: "3,5,6.5"."""
    values = []
    for part in str(text).split(","):
        if not part.strip():
            raise _type_error(f"{text!r} has an empty item; expected comma-separated numbers such as 3,5,6.5")
        values.append(item(part))
    return values


def nonempty_list(text):
    """Comma-separated names, none empty, none twice: "a,b"."""
    items = str(text).split(",")
    if any(not s for s in items):
        raise _type_error(f"{text!r} has an empty item; expected comma-separated names such as a,b")
    for k, s in enumerate(items):
        if s in items[:k]:
            raise _type_error(f"{s!r} is given twice; expected each name once")
    return items


def _path_problem(path):
    """Why `path` cannot be read as a file, or None."""
    if not os.path.lexists(path):
        return "no such file"
    if not os.path.exists(path):
        return "a broken symbolic link"
    if os.path.isdir(path):
        return "a folder, not a file"
    if not os.path.isfile(path):
        return "a special file (a device, pipe or socket), not a file"
    if not os.access(path, os.R_OK):
        return "not readable"
    return None


def existing_file(text):
    problem = _path_problem(text)
    if problem:
        raise _type_error(f"{text}: {problem}; expected an existing file")
    return text


def existing_dir(text):
    if not os.path.exists(text):
        raise _type_error(f"{text}: no such folder; expected an existing folder")
    if not os.path.isdir(text):
        raise _type_error(f"{text}: is {describe_existing(text)}, not a folder; expected an existing folder")
    return text


def executable(text):
    """A program: a path to an executable file, or a name found on PATH."""
    if os.sep not in text:  # a name is looked up on PATH (as subprocess does), not in this folder
        if shutil.which(text):
            return text
        here = f" (a file of that name is here: give ./{text})" if os.path.exists(text) else ""
        raise _type_error(f"{text}: no such program on PATH{here}; expected the crowdrecon executable "
                          "(such as build/release/cli/crowdrecon)")
    problem = _path_problem(text)
    if problem:
        raise _type_error(f"{text}: {problem}; expected the crowdrecon executable (such as build/release/cli/crowdrecon)")
    if not os.access(text, os.X_OK):
        raise _type_error(f"{text}: not executable; expected the crowdrecon executable")
    return text


def open_readonly(path):
    """An SQLite file opened read-only (never creates one)."""
    uri = pathlib.Path(path).resolve().as_uri() + "?mode=ro"
    return sqlite3.connect(uri, uri=True)


def sqlite_tables(path):
    """The table names of an SQLite file; ScriptError naming the file if it is not one."""
    problem = _path_problem(path)
    if problem:
        raise ScriptError(f"{path}: {problem}; expected an SQLite file")
    with open(path, "rb") as f:
        head = f.read(len(SQLITE_MAGIC))
    if head != SQLITE_MAGIC:
        raise ScriptError(f"{path}: is {describe_existing(path)}, not an SQLite file; expected an SQLite file")
    try:
        con = open_readonly(path)
        try:
            return {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        finally:
            con.close()
    except sqlite3.DatabaseError as e:
        raise ScriptError(f"{path}: cannot be read as SQLite ({e}); expected an SQLite file") from None


def require_tables(path, tables, expected):
    """ScriptError unless the SQLite file `path` has every table of `tables`."""
    have = sqlite_tables(path)
    missing = [t for t in tables if t not in have]
    if missing:
        raise ScriptError(f"{path}: has no {', '.join(missing)} table{'s' if len(missing) > 1 else ''}; "
                          f"expected {expected}")
    return have


def table_columns(path, table):
    con = open_readonly(path)
    try:
        return [r[1] for r in con.execute(f'PRAGMA table_info("{table}")')]
    finally:
        con.close()


# The tables a packed run file (run.frames "packed") leaves empty, holding its
# people in table frame_pack instead (docs/scenarios.md, "Packed frames").
PACKED_TABLES = ("trajectory_data", "person_state", "person_load")


def check_run_file(path, tables=(), expected=None):
    """A run file: an SQLite file whose `run` table exists (and the other tables the script reads).

    A script reads the tables itself: a run whose frames are packed, or a
    segment of a run in segments (its earlier frames in other files), is
    refused with what to do instead."""
    have = require_tables(path, ["run", *tables],
                          expected or "a crowdrecon run file (an SQLite file of `crowdrecon simulate`)")
    con = open_readonly(path)
    try:
        continues = con.execute("SELECT value FROM run WHERE key = 'continues'").fetchone()
    finally:
        con.close()
    if "frame_pack" in have and any(t in PACKED_TABLES for t in tables):
        raise ScriptError(f"{path}: its people's frames are packed (run.frames \"packed\"; table frame_pack), which this "
                          f"script does not read; give it the run with tables: crowdrecon export {path} -o RUN.sqlite "
                          "--tables")
    if continues:
        raise ScriptError(f"{path}: is a segment of a run in segments (it continues {continues[0]}); this script "
                          f"reads one file: give it the whole run: crowdrecon export {path} -o RUN.sqlite --tables")
    return have


def run_file(text):
    """argparse type=: a crowdrecon run file."""
    try:
        check_run_file(text)
    except ScriptError as e:
        raise _type_error(str(e)) from None
    return text


def check_sweep_dir(path, sqlite=True, csv_table=False):
    """A crowdrecon sweep folder: it holds results.sqlite (runs and sweep tables) and/or results.csv."""
    expected = ("a crowdrecon sweep folder (the -o folder of `crowdrecon sweep`, holding "
                + ("results.sqlite)" if sqlite else "results.csv)"))
    if not os.path.exists(path):
        raise ScriptError(f"{path}: no such folder; expected {expected}")
    if not os.path.isdir(path):
        raise ScriptError(f"{path}: is {describe_existing(path)}, not a folder; expected {expected}")
    if sqlite:
        db = os.path.join(path, "results.sqlite")
        if not os.path.exists(db):
            raise ScriptError(f"{path}: holds no results.sqlite (not a crowdrecon sweep folder); expected {expected}")
        require_tables(db, ["sweep", "runs"], "the results of a crowdrecon sweep")
    if csv_table:
        table = os.path.join(path, "results.csv")
        if _path_problem(table):
            raise ScriptError(f"{path}: holds no results.csv ({_path_problem(table)}); expected {expected}")
        header = csv_header(table)
        missing = [c for c in ("run_id", "variant", "seed", "status") if c not in header]
        if missing:
            raise ScriptError(f"{table}: has no column {', '.join(missing)}; expected the results table of a crowdrecon sweep")
    return path


def sweep_dir(text):
    """argparse type=: a sweep folder holding results.sqlite."""
    try:
        return check_sweep_dir(text)
    except ScriptError as e:
        raise _type_error(str(e)) from None


def sweep_dir_csv(text):
    """argparse type=: a sweep folder holding results.csv (the scripts that read the CSV)."""
    try:
        return check_sweep_dir(text, sqlite=False, csv_table=True)
    except ScriptError as e:
        raise _type_error(str(e)) from None


def sweep_inputs(folder):
    """The files of a sweep folder that a script must never overwrite: [(what, path)]."""
    return [(f"the sweep's {name}", os.path.join(folder, name))
            for name in ("results.sqlite", "results.csv", "runs", "phase")]


def sweep_variants(folder):
    """The variants of a sweep's runs table, in run order."""
    con = open_readonly(os.path.join(folder, "results.sqlite"))
    try:
        return list(dict.fromkeys(r[0] for r in con.execute("SELECT variant FROM runs ORDER BY run_index")))
    finally:
        con.close()


def csv_header(path):
    """The first row of a CSV file (after '#' comment lines), [] if none."""
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        for row in csv.reader(f):
            if row and not row[0].startswith("#"):
                return row
    return []


def require_csv_columns(path, columns, expected):
    problem = _path_problem(path)
    if problem:
        raise ScriptError(f"{path}: {problem}; expected {expected}")
    header = csv_header(path)
    missing = [c for c in columns if c not in header]
    if missing:
        raise ScriptError(f"{path}: has no column{'s' if len(missing) > 1 else ''} {', '.join(missing)}; expected {expected}")


def read_json_file(path, expected):
    problem = _path_problem(path)
    if problem:
        raise ScriptError(f"{path}: {problem}; expected {expected}")
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (ValueError, UnicodeDecodeError) as e:
        raise ScriptError(f"{path}: not valid JSON ({one_line(e)}); expected {expected}") from None


# ---------------------------------------------------------------- what is there

def _head(path, n=1024):
    try:
        with open(path, "rb") as f:
            return f.read(n)
    except OSError:
        return b""


def _describe_file(path):
    try:
        size = os.path.getsize(path)
    except OSError:
        size = 0
    if size == 0:
        return "an empty file"
    head = _head(path)
    if head.startswith(SQLITE_MAGIC):
        return "a SQLite file"
    if head.startswith(b"\x89PNG"):
        return "a PNG picture"
    if head.startswith(b"%PDF"):
        return "a PDF file"
    stripped = head.lstrip()
    if stripped.startswith(b"<") and b"<svg" in head:
        return "an SVG picture"
    if stripped[:1] in (b"{", b"["):
        return "a JSON file"
    if stripped.startswith(b"<"):
        return "an XML or HTML file"
    text = all(c >= 0x20 or c in (0x09, 0x0A, 0x0D) for c in head)
    return f"{'a text file' if text else 'a binary file'} of {size} bytes"


def _describe_folder(path):
    try:
        names = sorted(os.listdir(path))
    except OSError:
        names = []
    if not names:
        return "an empty folder"
    shown = ", ".join(n if len(n) <= 40 else n[:37] + "..." for n in names[:3]) + (", ..." if len(names) > 3 else "")
    return f"a folder holding {len(names)} {'entry' if len(names) == 1 else 'entries'} ({shown})"


def describe_existing(path):
    """What is at `path`, for messages: "a JSON file", "a folder holding 3 entries (...)", "nothing"."""
    if not os.path.lexists(path):
        return "nothing"
    if not os.path.exists(path):
        return "a broken symbolic link"
    if os.path.isdir(path):
        return _describe_folder(path)
    if os.path.isfile(path):
        return _describe_file(path)
    return "a special file (a device, pipe or socket)"


def same_path(a, b):
    """The same file or folder: through symbolic and hard links where both exist, else by the
    resolved, normalised paths (an output not yet written)."""
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except OSError:
        pass
    return os.path.realpath(os.path.abspath(a)) == os.path.realpath(os.path.abspath(b))


# ---------------------------------------------------------------- previous outputs (is_previous predicates)

def is_partial_name(name):
    """A temporary name of write_whole's form (".NAME.partial-PID.EXT")."""
    return name.startswith(".") and ".partial-" in name


def text_head(path, n=1024):
    """The first n bytes of a file as text ("" if unreadable)."""
    return _head(path, n).decode("utf-8", "replace")


def first_line_has(*parts):
    """A file whose first line holds every one of `parts`."""
    def check(path):
        line = text_head(path, 2048).split("\n")[0]
        return os.path.isfile(path) and all(p in line for p in parts)
    return check


def starts_with(prefix):
    """A file whose first bytes are `prefix` (str or bytes)."""
    raw = prefix.encode() if isinstance(prefix, str) else prefix

    def check(path):
        return os.path.isfile(path) and _head(path, len(raw)) == raw
    return check


def csv_starting(*columns):
    """A CSV file whose header begins with these columns."""
    return starts_with(",".join(columns))


def is_json_with(key, value):
    """A JSON file whose top-level object has key = value."""
    def check(path):
        try:
            with open(path, encoding="utf-8") as f:
                d = json.load(f)
        except (OSError, ValueError, UnicodeDecodeError):
            return False
        return isinstance(d, dict) and d.get(key) == value
    return check


def is_svg(path):
    head = _head(path).lstrip()
    return head.startswith(b"<") and b"<svg" in head


def is_png(path):
    return _head(path, 4) == b"\x89PNG"


def is_run_file(path):
    """A crowdrecon run file (its run table says format crowdrecon-run)."""
    if _head(path, len(SQLITE_MAGIC)) != SQLITE_MAGIC:
        return False
    try:
        con = open_readonly(path)
        try:
            row = con.execute("SELECT value FROM run WHERE key = 'format'").fetchone()
        finally:
            con.close()
    except sqlite3.DatabaseError:
        return False
    return row is not None and row[0] == "crowdrecon-run"


def _match(name, patterns):
    return any(fnmatch.fnmatchcase(name, p) for p in patterns)


def folder_of(*patterns):
    """A folder whose every entry matches one of the patterns (fnmatch; write_whole's partials too):
    a folder that holds only this script's own entries."""
    def check(path):
        try:
            names = os.listdir(path)
        except OSError:
            return False
        return all(_match(n, patterns) or is_partial_name(n) for n in names)
    return check


def folder_with(files):
    """A folder holding at least one of the script's own files: `files` maps a name (or fnmatch pattern)
    to the predicate of that file's kind. The folder is written into; each file is checked on its own."""
    def check(path):
        try:
            names = os.listdir(path)
        except OSError:
            return False
        for n in names:
            for pattern, is_previous in files.items():
                if fnmatch.fnmatchcase(n, pattern) and is_previous(os.path.join(path, n)):
                    return True
        return False
    return check


# ---------------------------------------------------------------- the output check

class Output:
    """An output a script writes: how the user named it (an option such as "-o"; "" for a file the script
    names inside an output folder: messages then give its path alone), its path, what kind it is (for messages: "the bottleneck study's results.csv")
    and how a previous output of that kind is recognised. folder: a folder rather than a file."""

    def __init__(self, option, path, kind, is_previous=None, folder=False):
        self.option, self.path, self.kind, self.is_previous, self.folder = option, path, kind, is_previous, folder

    def __repr__(self):
        return f"Output({self.option!r}, {self.path!r})"


def _shorten(text, n=200):
    text = str(text)
    return text if len(text) <= n else text[:n - 3] + "..."


def _normalise_outputs(outputs, is_previous):
    out = []
    for o in outputs:
        if isinstance(o, Output):
            if o.is_previous is None and is_previous is not None:
                o = Output(o.option, o.path, o.kind, is_previous, o.folder)
            out.append(o)
        else:
            option, path, *rest = o
            kind = rest[0] if rest else "an output of this script"
            out.append(Output(option, path, kind, is_previous))
    return [o for o in out if o.path not in (None, "")]


def _normalise_inputs(inputs):
    out = []
    for i in inputs:
        if isinstance(i, (tuple, list)):
            what, path = i
        else:
            what, path = "an input", i
        if path not in (None, ""):
            out.append((what, os.fspath(path)))
    return out


def _check_one(o, inputs, force):
    path = os.fspath(o.path)
    where = f"{o.option} {_shorten(path)}" if o.option and o.option != path else _shorten(path)  # no option: the path
    for what, inp in inputs:
        if same_path(path, inp):
            raise ScriptError(f"{where}: is an input; refusing to overwrite it ({what}: {_shorten(inp)}), "
                              "not even with --force; expected a name that no input has")
    name = os.path.basename(path)
    if not o.folder and (path.endswith(os.sep) or (os.altsep and path.endswith(os.altsep)) or name in ("", ".", "..")):
        raise ScriptError(f"{where}: names a folder, not {o.kind}; expected a file name")
    # The nearest existing folder above it must be a folder.
    parent = os.path.dirname(os.path.abspath(path))
    while parent and not os.path.lexists(parent):
        up = os.path.dirname(parent)
        if up == parent:
            break
        parent = up
    if os.path.lexists(parent) and not os.path.isdir(parent):
        raise ScriptError(f"{where}: {_shorten(parent)} is {describe_existing(parent)}, not a folder; "
                          "expected a path whose folders are folders")
    if not os.path.lexists(path):
        return  # nothing there: nothing to lose
    there = describe_existing(path)
    folder = os.path.isdir(path)
    if not o.folder and folder:
        raise ScriptError(f"{where}: exists and is {there}, not {o.kind}; a folder is never replaced by a file, "
                          "not even with --force; expected a file name")
    if o.folder and not folder:
        raise ScriptError(f"{where}: exists and is {there}, not {o.kind}; expected the name of a folder")
    if not folder and not os.path.isfile(path):
        raise ScriptError(f"{where}: exists and is {there}, not {o.kind}; expected another name")
    if folder:
        try:
            empty = not os.listdir(path)
        except OSError as e:
            raise ScriptError(f"{where}: cannot be read ({e.strerror}); expected a folder this script can write into") from None
    else:
        empty = os.path.getsize(path) == 0
    if empty or force or (o.is_previous is not None and o.is_previous(path)):
        return
    raise ScriptError(f"{where}: exists and is {there}, not {o.kind}; expected another name, or --force "
                      + ("(which writes into the folder and deletes nothing in it)" if folder else "(which replaces it)"))


def check_outputs(outputs, inputs, force=False, is_previous=None):
    """Raises ScriptError if writing `outputs` could overwrite an input or destroy anything (the rules in
    this module's header). outputs: Output objects, or (option, path[, kind]) tuples whose previous outputs
    `is_previous` recognises; inputs: (what, path) tuples or paths. Paths that are None or "" are skipped.
    Call it before any work."""
    outs = _normalise_outputs(outputs, is_previous)
    ins = _normalise_inputs(inputs)
    for i, o in enumerate(outs):
        for earlier in outs[:i]:
            if same_path(o.path, earlier.path):
                raise ScriptError(f"{earlier.option or earlier.path} and {o.option or o.path} both name {_shorten(o.path)}; "
                                  "expected each output its own name")
        _check_one(o, ins, force)


# ---------------------------------------------------------------- writing whole files

def partial_path(path):
    """The temporary name next to `path` with the same extension: ".NAME.partial-PID.EXT"."""
    folder, name = os.path.split(os.fspath(path))
    stem, ext = os.path.splitext(name)
    return os.path.join(folder, f".{stem}.partial-{os.getpid()}{ext}")


def _running(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_partials(path):
    """Removes the partial files of `path` that killed writers left (their process no longer runs)."""
    folder, name = os.path.split(os.path.abspath(os.fspath(path)))
    stem, ext = os.path.splitext(name)
    pattern = re.compile(re.escape(f".{stem}.partial-") + r"([0-9]+)" + re.escape(ext) + "$")
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for n in names:
        m = pattern.match(n)
        if m and int(m.group(1)) != os.getpid() and not _running(int(m.group(1))):
            with contextlib.suppress(OSError):
                os.remove(os.path.join(folder, n))
                removed.append(os.path.join(folder, n))
    return removed


class TerminateAsExit:
    """While held (in the main thread), SIGTERM and SIGHUP raise SystemExit, so that a killed script
    removes its partial file on the way out."""

    def __enter__(self):
        self.saved = {}
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGTERM, signal.SIGHUP):
                try:
                    self.saved[sig] = signal.signal(sig, self._raise)
                except (ValueError, OSError):
                    pass
        return self

    @staticmethod
    def _raise(signum, frame):
        raise SystemExit(128 + signum)

    def __exit__(self, *exc):
        for sig, handler in self.saved.items():
            signal.signal(sig, handler)
        return False


@contextlib.contextmanager
def whole_file(path, mode="w", **open_args):
    """A file object over a temporary name beside `path`; renamed over `path` when the block ends
    without an error, removed otherwise (an exception, Ctrl-C, SIGTERM). Creates the folder if needed."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    remove_stale_partials(path)
    tmp = partial_path(path)
    with TerminateAsExit():
        try:
            with open(tmp, mode, **open_args) as f:
                yield f
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.remove(tmp)
            raise


def write_whole(path, data, encoding="utf-8"):
    """Writes `data` (str or bytes) to `path` whole: a temporary file in the same folder, then os.replace."""
    if isinstance(data, str):
        data = data.encode(encoding)
    with whole_file(path, "wb") as f:
        f.write(data)


def refuse_repeated(paths, what):
    """ScriptError naming the second of two entries of `paths` that are the same file (also through links)."""
    for i, p in enumerate(paths):
        for q in paths[:i]:
            if same_path(p, q):
                raise ScriptError(f"{p}: given twice (also as {q}); expected each {what} once")
