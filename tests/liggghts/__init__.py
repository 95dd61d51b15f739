"""tests/liggghts as a package: its helpers are imported as tests.liggghts.NAME."""
