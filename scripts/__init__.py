"""jdem's Python tooling, one package: the engines' runner (scripts.engines), the deck generator,
the benchmarks and studies, the mixing analysis (scripts.mixing).

Modules import each other as `scripts.NAME` (or relatively inside a sub-package), never by
editing sys.path.  The repository root must therefore be on the module path, which is done in
one way: PYTHONPATH is the repository root.  The Makefile exports it for every recipe,
tests/run_tests.py sets it for every suite and scripts.engines for every script it starts.
By hand, from the repository root:

    /usr/bin/python3 -m scripts.NAME ARGS          (or PYTHONPATH=. /usr/bin/python3 scripts/NAME.py)
"""
