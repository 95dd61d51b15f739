"""tests/inlet as a package: its helpers are imported as tests.inlet.NAME."""
