#!/usr/bin/python3
"""The fault-injection suite: runs every tests/faults/test_*.py (sorted) and passes its lines
through; exits non-zero if any file failed.  faults_common.py describes the helpers.

Run:  /usr/bin/python3 tests/faults/run_faults.py [test_names.py ...]
"""
import glob
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def main(argv):
    tests = ([os.path.join(HERE, a) for a in argv[1:]] or
             sorted(glob.glob(os.path.join(HERE, "test_*.py"))))
    failed = 0
    for t in tests:
        proc = subprocess.run(["/usr/bin/python3", t], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, errors="replace")
        sys.stdout.write(proc.stdout)
        if proc.returncode != 0:
            failed += 1
            if "\nFAIL " not in "\n" + proc.stdout:
                print(f"FAIL {os.path.basename(t)}: exit status {proc.returncode}")
        sys.stdout.flush()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
