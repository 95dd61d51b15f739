"""tests/mesh as a package: the mesh-wall checks, imported as tests.mesh.NAME (scripts/mesh_wall_bench.py reuses its STL grid)."""
