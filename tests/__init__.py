"""jdem's test suites (run by tests/run_tests.py with the repository root on PYTHONPATH: see
scripts/__init__.py).  Shared helpers are imported as tests.engine.engine_common,
tests.liggghts.liggghts_common, tests.faults.faults_common, tests.fuzz.fuzz_common."""
