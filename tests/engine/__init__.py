"""tests/engine as a package: its helpers are imported as tests.engine.NAME."""
