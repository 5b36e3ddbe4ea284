"""The command lines of hsactl and hsad, run as built: both print the project's version, hsactl
answers a mistyped command with the one meant, wherever the global options put it, and hsad
refuses more operator keys than it signs each status for.

    python3 test_command_line.py HSACTL HSAD SOURCE_DIR
"""
import os
import re
import secrets
import subprocess
import sys
import tempfile
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

    def test_hsad_refuses_more_keys_than_it_signs_each_status_for(self):
        with tempfile.TemporaryDirectory() as keys:
            os.chmod(keys, 0o700)
            for i in range(65):
                path = os.path.join(keys, f"op{i}.key")
                with os.fdopen(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600), "w") as f:
                    f.write(secrets.token_hex(32) + "\n")
            config = f"{SOURCE}/systemd/hsad-sim.toml"
            r = run(HSAD, "--check-config", config, "--key-dir", keys)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertIn(f"{keys} holds 65 operator keys; hsad signs each status for every key it holds, at most 64",
                          r.stderr)
            os.unlink(os.path.join(keys, "op64.key"))
            r = run(HSAD, "--check-config", config, "--key-dir", keys)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertRegex(r.stdout, r"(?m)^  system        \S+ \(commands signed for another system are refused\)$")


if __name__ == "__main__":
    unittest.main(verbosity=2)
