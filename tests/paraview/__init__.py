"""tests/paraview as a package: its helpers are imported as tests.paraview.NAME."""
