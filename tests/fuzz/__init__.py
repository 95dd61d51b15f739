"""tests/fuzz as a package: its helpers are imported as tests.fuzz.NAME."""
