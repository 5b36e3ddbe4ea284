"""hsactl's man page and bash completion name every subcommand hsactl has, the man pages render
without a warning, and the completion script is valid bash.

    python3 test_hsactl_docs.py HSACTL SOURCE_DIR
"""
import re
import subprocess
import sys
import unittest

HSACTL, SOURCE = sys.argv[1:3]
del sys.argv[1:3]


def subcommands():
    """The subcommands `hsactl --help` lists."""
    out = subprocess.run([HSACTL, "--help"], capture_output=True, text=True, timeout=30).stdout
    section = out.split("Subcommands:", 1)[1]
    return re.findall(r"(?m)^  ([a-z0-9]+)\s", section)


class HsactlDocsTest(unittest.TestCase):
    def test_every_subcommand_is_in_the_man_page_and_the_completion(self):
        names = subcommands()
        self.assertGreater(len(names), 10, names)
        with open(f"{SOURCE}/docs/man/hsactl.1") as f:
            man = f.read()
        with open(f"{SOURCE}/tools/hsactl/hsactl.bash-completion") as f:
            completion = f.read()
        listed = re.search(r'local commands="([^"]+)"', completion).group(1).split()
        for name in names:
            self.assertRegex(man, rf"(?m)^\.(B|BI|BR) {name}\b|\\fB{name}\b", f"{name} not in hsactl.1")
            self.assertIn(name, listed, f"{name} not completed")
        self.assertEqual(sorted(listed), sorted(names), "the completion lists a command hsactl does not have")

    def test_the_man_pages_render_without_warnings(self):
        for page in ("docs/man/hsactl.1", "docs/man/hsad.8"):
            r = subprocess.run(["groff", "-ww", "-z", "-man", f"{SOURCE}/{page}"], capture_output=True, text=True)
            self.assertEqual((r.returncode, r.stderr), (0, ""), page)

    def test_the_completion_script_is_valid_bash(self):
        r = subprocess.run(["bash", "-n", f"{SOURCE}/tools/hsactl/hsactl.bash-completion"],
                           capture_output=True, text=True)
        self.assertEqual((r.returncode, r.stderr), (0, ""))


if __name__ == "__main__":
    unittest.main(verbosity=2)
