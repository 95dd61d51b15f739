"""tests/mixing as a package: its helpers are imported as tests.mixing.NAME."""
