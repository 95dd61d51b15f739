"""tests/faults as a package: its helpers are imported as tests.faults.NAME."""
