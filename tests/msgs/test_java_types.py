"""The Java types in hsa-msgs.jar (what lcm-spy decodes hsa's channels with) are the C++ types:
every type is in the jar, and its LCM fingerprint is the one the C++ code computes, so lcm-spy
matches each channel's messages to its type.

    python3 test_java_types.py PRINT_FINGERPRINTS HSA_MSGS_JAR LCM_JAR
"""
import os
import subprocess
import sys
import tempfile
import unittest

PRINTER, MSGS_JAR, LCM_JAR = sys.argv[1:4]
del sys.argv[1:4]

JAVA_PRINTER = """
public class Fingerprints {
  public static void main(String[] args) throws Exception {
    for (String name : args) {
      long fingerprint = Class.forName(name).getField("LCM_FINGERPRINT").getLong(null);
      System.out.println(name + " " + fingerprint);
    }
  }
}
"""


class JavaTypesTest(unittest.TestCase):
    def test_every_type_has_the_cpp_fingerprint_in_java(self):
        cpp = subprocess.run([PRINTER], capture_output=True, text=True, check=True, timeout=30).stdout.split("\n")
        expected = dict(line.split() for line in cpp if line)
        self.assertEqual(len(expected), 5, cpp)
        with tempfile.TemporaryDirectory() as tmp:
            with open(os.path.join(tmp, "Fingerprints.java"), "w") as f:
                f.write(JAVA_PRINTER)
            classpath = os.pathsep.join([LCM_JAR, MSGS_JAR, tmp])
            subprocess.run(["javac", "-cp", classpath, "-d", tmp, os.path.join(tmp, "Fingerprints.java")],
                           check=True, timeout=120)
            java = subprocess.run(["java", "-cp", classpath, "Fingerprints", *expected],
                                  capture_output=True, text=True, timeout=120)
        self.assertEqual(java.returncode, 0, java.stderr)
        self.assertEqual(dict(line.split() for line in java.stdout.split("\n") if line), expected)


if __name__ == "__main__":
    unittest.main(verbosity=2)
