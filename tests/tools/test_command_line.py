"""The command lines of hsactl and hsad, run as built: both print the project's version, and
hsactl answers a mistyped command with the one meant, wherever the global options put it.

    python3 test_command_line.py HSACTL HSAD SOURCE_DIR
"""
import re
import subprocess
import sys
import unittest

HSACTL, HSAD, SOURCE = sys.argv[1:4]
del sys.argv[1:4]


def run(*args):
    return subprocess.run(list(args), capture_output=True, text=True, timeout=30)


class CommandLineTest(unittest.TestCase):
    def test_both_programs_print_the_projects_version(self):
        with open(f"{SOURCE}/CMakeLists.txt") as f:
            version = re.search(r"project\(hsa VERSION ([0-9.]+)", f.read()).group(1)
        for program, name in ((HSACTL, "hsactl"), (HSAD, "hsad")):
            r = run(program, "--version")
            self.assertEqual((r.returncode, r.stdout, r.stderr), (0, f"{name} {version}\n", ""), program)

    def test_a_mistyped_command_names_the_one_meant(self):
        for args in (["stauts"], ["--axis", "stauts", "stauts"], ["--axis=x", "stauts", "--json"]):
            r = run(HSACTL, *args)
            self.assertEqual(r.returncode, 2, args)
            self.assertIn("hsactl: unknown command 'stauts'; did you mean 'status'?", r.stderr, args)

    def test_a_word_near_no_command_is_only_named(self):
        r = run(HSACTL, "launch")
        self.assertEqual(r.returncode, 2)
        self.assertIn("unknown command 'launch'", r.stderr)
        self.assertNotIn("did you mean", r.stderr)

    def test_no_command_at_all_is_still_clis_own_error(self):
        r = run(HSACTL, "--axis", "stauts")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("A subcommand is required", r.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
