#!/usr/bin/env python3
"""scripts/script_guard.py, the output rules and argument checks the Python
scripts share with crowdrecon (issue 65; common/include/crowdrecon/common/
output_path.hpp): an input is never an output (directly, through a symbolic
link, through a hard link, by another spelling), not even with force; a folder
is never replaced by a file; a foreign file is replaced only with force, a
previous output always; two outputs never name one path; a write that fails or
is killed leaves the previous file as it was and no partial file; a bad
argument is one line and exit status 2.

    test_script_guard.py        (standard library only; exit status 0 when every test passes)
"""
import argparse
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import unittest

SCRIPTS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "scripts")
sys.path.insert(0, SCRIPTS)
import script_guard as guard  # noqa: E402

PREVIOUS = guard.starts_with("# made by the test\n")


def output(path, option="-o", previous=PREVIOUS):
    return guard.Output(option, path, "a table of the test", previous)


class Scratch(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="script-guard-")
        self.old_cwd = os.getcwd()
        os.chdir(self.dir)

    def tearDown(self):
        os.chdir(self.old_cwd)
        subprocess.run(["rm", "-rf", self.dir], check=False)

    def write(self, name, text):
        os.makedirs(os.path.dirname(os.path.abspath(name)), exist_ok=True)
        with open(name, "w") as f:
            f.write(text)
        return name

    def read(self, name):
        with open(name) as f:
            return f.read()

    def refused(self, outputs, inputs=(), force=False, says=""):
        with self.assertRaises(guard.ScriptError) as e:
            guard.check_outputs(outputs, inputs, force)
        message = str(e.exception)
        self.assertNotIn("\n", message)
        self.assertIn(says, message)
        return message


class InputNeverAnOutput(Scratch):
    def setUp(self):
        super().setUp()
        self.write("run.sqlite", "the input\n")

    def test_the_same_name(self):
        self.refused([output("run.sqlite")], [("a run file", "run.sqlite")], says="is an input")

    def test_another_spelling(self):
        os.mkdir("sub")
        self.refused([output("sub/../run.sqlite")], [("a run file", "./run.sqlite")], says="is an input")
        self.refused([output(os.path.join(self.dir, "run.sqlite"))], ["run.sqlite"], says="is an input")

    def test_a_symbolic_link(self):
        os.symlink("run.sqlite", "link.sqlite")
        self.refused([output("link.sqlite")], [("a run file", "run.sqlite")], says="is an input")
        # ... and the input named through the link, the output directly
        self.refused([output("run.sqlite")], [("a run file", "link.sqlite")], says="is an input")

    def test_a_link_to_the_folder(self):
        os.symlink(self.dir, "here")
        self.refused([output("here/run.sqlite")], ["run.sqlite"], says="is an input")

    def test_a_hard_link(self):
        os.link("run.sqlite", "hard.sqlite")
        self.refused([output("hard.sqlite")], [("a run file", "run.sqlite")], says="is an input")

    def test_not_even_with_force_nor_as_a_previous_output(self):
        self.refused([output("run.sqlite", previous=lambda p: True)], ["run.sqlite"], force=True, says="not even with --force")

    def test_an_input_folder(self):
        os.mkdir("sweep")
        self.refused([guard.Output("-o", "sweep", "a folder of the test", folder=True)], [("the sweep", "sweep")],
                     force=True, says="is an input")

    def test_input_unchanged(self):
        with self.assertRaises(guard.ScriptError):
            guard.check_outputs([output("run.sqlite")], ["run.sqlite"], True)
        self.assertEqual(self.read("run.sqlite"), "the input\n")


class Existing(Scratch):
    def test_nothing_there(self):
        guard.check_outputs([output("new.md")], [], False)
        guard.check_outputs([output("a/b/new.md")], [], False)

    def test_a_folder_named_as_a_file(self):
        os.mkdir("results")
        self.refused([output("results")], says="a folder is never replaced by a file")
        self.refused([output("results")], force=True, says="a folder is never replaced by a file")
        os.mkdir("full")
        self.write("full/notes.txt", "mine\n")
        self.refused([output("full")], force=True, says="a folder holding 1 entry (notes.txt)")

    def test_a_name_ending_with_a_separator(self):
        self.refused([output("out/")], says="names a folder")

    def test_a_foreign_file(self):
        self.write("notes.md", "my notes\n")
        self.refused([output("notes.md")], says="a text file of 9 bytes")
        self.refused([output("notes.md")], says="--force (which replaces it)")
        guard.check_outputs([output("notes.md")], [], True)  # with force: replaced
        self.assertEqual(self.read("notes.md"), "my notes\n")  # (the check itself writes nothing)

    def test_a_previous_output_is_replaced(self):
        self.write("table.md", "# made by the test\n| a |\n")
        guard.check_outputs([output("table.md")], [], False)
        guard.write_whole("table.md", "# made by the test\n| b |\n")
        self.assertEqual(self.read("table.md"), "# made by the test\n| b |\n")

    def test_an_empty_file_holds_nothing_to_lose(self):
        self.write("empty.md", "")
        guard.check_outputs([output("empty.md")], [], False)

    def test_a_broken_link_or_a_file_as_a_folder(self):
        os.symlink("nowhere", "dangling.md")
        self.refused([output("dangling.md")], force=True, says="a broken symbolic link")
        self.write("file", "x\n")
        self.refused([output("file/table.md")], force=True, says="not a folder")

    def test_two_outputs_one_path(self):
        self.refused([output("d.md", "-o"), output("./d.md", "--csv")], says="-o and --csv both name")
        self.write("d.md", "")
        os.symlink("d.md", "e.md")
        self.refused([output("d.md", "-o"), output("e.md", "--csv")], force=True, says="both name")

    def test_folders(self):
        ours = guard.folder_with({"table.md": PREVIOUS})
        folder = lambda p: guard.Output("OUT", p, "a folder of the test", ours, folder=True)
        guard.check_outputs([folder("new")], [], False)
        os.mkdir("empty")
        guard.check_outputs([folder("empty")], [], False)
        self.write("previous/table.md", "# made by the test\n")
        self.write("previous/notes.txt", "kept\n")
        guard.check_outputs([folder("previous")], [], False)
        self.write("foreign/notes.txt", "mine\n")
        self.refused([folder("foreign")], says="(which writes into the folder and deletes nothing in it)")
        guard.check_outputs([folder("foreign")], [], True)
        self.write("a-file", "x\n")
        self.refused([folder("a-file")], force=True, says="expected the name of a folder")
        self.assertEqual(self.read("foreign/notes.txt"), "mine\n")
        only = guard.folder_of("*.sqlite", "log.txt")
        self.write("runs/a.sqlite", "")
        self.write("runs/log.txt", "")
        self.assertTrue(only("runs"))
        self.write("runs/notes.txt", "")
        self.assertFalse(only("runs"))


class WrittenWhole(Scratch):
    def test_write_replaces(self):
        guard.write_whole("out.csv", "a,b\n1,2\n")
        self.assertEqual(self.read("out.csv"), "a,b\n1,2\n")
        guard.write_whole("out.csv", b"bytes\n")
        self.assertEqual(self.read("out.csv"), "bytes\n")
        guard.write_whole("deep/er/out.csv", "x")
        self.assertEqual(self.read("deep/er/out.csv"), "x")
        self.assertEqual(sorted(os.listdir(".")), ["deep", "out.csv"])

    def test_an_error_leaves_the_previous_file_and_no_partial(self):
        self.write("out.csv", "previous\n")
        with self.assertRaises(RuntimeError):
            with guard.whole_file("out.csv") as f:
                f.write("half of the new ")
                raise RuntimeError("interrupted")
        self.assertEqual(self.read("out.csv"), "previous\n")
        self.assertEqual(os.listdir("."), ["out.csv"])

    def test_an_error_leaves_no_new_file(self):
        with self.assertRaises(KeyboardInterrupt):
            with guard.whole_file("new.csv", "w", newline="") as f:
                f.write("half")
                raise KeyboardInterrupt
        self.assertEqual(os.listdir("."), [])

    def test_killed_while_writing(self):
        self.write("out.md", "previous\n")
        program = textwrap.dedent(f"""
            import sys, time
            sys.path.insert(0, {SCRIPTS!r})
            import script_guard
            with script_guard.whole_file("out.md") as f:
                f.write("half of it")
                f.flush()
                print("writing", flush=True)
                time.sleep(30)
                f.write("the rest")
        """)
        p = subprocess.Popen([sys.executable, "-c", program], stdout=subprocess.PIPE, text=True)
        self.assertEqual(p.stdout.readline().strip(), "writing")
        self.assertEqual(len(os.listdir(".")), 2)  # out.md and its partial
        p.send_signal(signal.SIGTERM)
        p.wait(timeout=20)
        p.stdout.close()
        self.assertNotEqual(p.returncode, 0)
        self.assertEqual(self.read("out.md"), "previous\n")
        self.assertEqual(os.listdir("."), ["out.md"])

    def test_a_killed_writers_partial_is_removed(self):
        # A partial whose writer no longer runs (SIGKILL leaves one): removed by the next write.
        p = subprocess.Popen([sys.executable, "-c", "pass"])
        p.wait()
        stale = f".out.partial-{p.pid}.md"
        self.write(stale, "half")
        guard.write_whole("out.md", "whole\n")
        self.assertEqual(sorted(os.listdir(".")), ["out.md"])
        self.assertTrue(guard.is_partial_name(stale))


class Arguments(unittest.TestCase):
    def test_validators(self):
        self.assertEqual(guard.positive_int("3"), 3)
        self.assertEqual(guard.positive_float("0.1"), 0.1)
        self.assertEqual(guard.fraction("1"), 1.0)
        self.assertEqual(guard.float_list("3,5,6.5"), [3.0, 5.0, 6.5])
        self.assertEqual(guard.nonempty_list("a,b"), ["a", "b"])
        for check, text in [(guard.positive_int, "0"), (guard.positive_int, "1.5"), (guard.positive_int, "x"),
                            (guard.positive_float, "0"), (guard.positive_float, "nan"), (guard.positive_float, "inf"),
                            (guard.nonnegative_float, "-1"), (guard.fraction, "1.5"), (guard.float_list, "3,,4"),
                            (guard.nonempty_list, "a,a"), (guard.nonempty_list, "a,"),
                            (guard.int_between(2, 10), "1"), (guard.existing_file, "/nowhere"),
                            (guard.existing_file, "/"), (guard.existing_dir, "/nowhere"), (guard.run_file, "/"),
                            (guard.sweep_dir, "/nowhere"), (guard.executable, "/nowhere/crowdrecon")]:
            with self.assertRaises(argparse.ArgumentTypeError, msg=f"{check.__name__}({text!r})") as e:
                check(text)
            self.assertIn("expected", str(e.exception))

    def run_script(self, body, *args):
        program = f"import sys\nsys.path.insert(0, {SCRIPTS!r})\nimport script_guard as guard\n" + textwrap.dedent(body)
        return subprocess.run([sys.executable, "-c", program, *args], capture_output=True, text=True)

    def test_a_bad_argument_is_one_line_and_status_2(self):
        r = self.run_script("""
            p = guard.ArgumentParser(prog="demo.py")
            p.add_argument("--scale", type=guard.positive_float, default=1.0)
            p.parse_args()
        """, "--scale", "0")
        self.assertEqual(r.returncode, 2)
        self.assertEqual(r.stdout, "")
        self.assertEqual(len(r.stderr.splitlines()), 1, r.stderr)
        self.assertTrue(r.stderr.startswith("demo.py: error: argument --scale: 0 "), r.stderr)
        self.assertIn("expected a number above 0", r.stderr)

    def test_a_script_error_is_one_line_and_status_2(self):
        r = self.run_script("""
            def main():
                raise guard.ScriptError("RUN: no run table; expected a crowdrecon run file")
            guard.run_main(main)
        """)
        self.assertEqual(r.returncode, 2)
        self.assertEqual(r.stderr, "-c: error: RUN: no run table; expected a crowdrecon run file\n")
        self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=1)
