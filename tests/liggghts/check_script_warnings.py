#!/usr/bin/python3
"""check_script_warnings.py — a hand-written LIGGGHTS script is told what gran/jiang ignores.

    tests/liggghts/check_script_warnings.py

Builds nothing (run `make` first).  A deck as a LIGGGHTS user writes it (two spheres on a floor,
`pair_style gran/jiang`) with a stock `fix wall/gran` floor and the hysteresis tutorial's
`coefficientPlasticityDepth`, run twice (two `run` commands): the log must hold exactly one
warning naming the wall fix and one naming the property, with their exact text, and the run
must complete.  The same deck with `fix wall/jiang` and without the property has no warning.
And poissonsRatio 0.5 (incompressible) is accepted.  One PASS/FAIL line per check.
"""
import os
import re
import sys
import tempfile

from tests.liggghts.liggghts_common import Checks, granular_deck_head, run_deck

DECK = granular_deck_head("-0.1 0.1 -0.1 0.1 -0.01 0.2", "{nu}") + """{extra}
pair_style gran/jiang
pair_coeff * *
timestep 1.0e-5
create_atoms 1 single 0 0 0.01 units box
create_atoms 1 single 0.03 0 0.01 units box
set group all diameter 0.01 density 2500
{wall}
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
run 200
run 200
"""
STOCK_WALL = "fix floor all wall/gran model hertz tangential history primitive type 2 zplane 0.0"
OUR_WALL = ("fix floor all wall/jiang plane corners -0.1 -0.1 0 0.1 -0.1 0 0.1 0.1 0 -0.1 0.1 0 "
            "type 2")
PLASTICITY = "fix m5 all property/global coefficientPlasticityDepth peratomtypepair 2 0.5 0.5 0.5 0.5"
WALL_WARNING = ("WARNING: fix floor (wall/gran) evaluates its wall with LIGGGHTS' own contact "
                "model, not the Jiang (2021) law of pair_style gran/jiang: the run mixes two "
                "contact laws; use fix wall/jiang for plane, cylinder and mesh walls (docs/liggghts.md)")
PROPERTY_WARNING = ("WARNING: fix m5 (property/global coefficientPlasticityDepth) is not used by "
                    "pair_style gran/jiang: the Jiang (2021) law has no such parameter, so it has "
                    "no effect on the contacts")


def run_script(tmp, name, **fields):
    """DECK with FIELDS in TMP/NAME/in.deck, run: (exit status, log, output)."""
    d = os.path.join(tmp, name)
    os.mkdir(d)
    with open(os.path.join(d, "in.deck"), "w") as f:
        f.write(DECK.format(**fields))
    return run_deck(d, "in.deck")


def count(log, line):
    return sum(1 for l in log.splitlines() if re.sub(r" \([^()]*:\d+\)$", "", l) == line)


def main():
    c = Checks()
    with tempfile.TemporaryDirectory() as tmp:
        rc, log, out = run_script(tmp, "stock", nu="0.45", extra=PLASTICITY, wall=STOCK_WALL)
        c.check("stock wall/gran and a foreign property: the run completes", rc == 0,
                out[-800:] + log[-1500:])
        c.check("the wall/gran warning, once in two runs (%d)" % count(log, WALL_WARNING),
                count(log, WALL_WARNING) == 1, log[-2500:])
        c.check("the property warning, once in two runs (%d)" % count(log, PROPERTY_WARNING),
                count(log, PROPERTY_WARNING) == 1, log[-2500:])
        rc, log, out = run_script(tmp, "ours", nu="0.5", extra="", wall=OUR_WALL)
        c.check("fix wall/jiang, no foreign property, poissonsRatio 0.5: the run completes",
                rc == 0, out[-800:] + log[-1500:])
        c.check("... and no warning", "WARNING" not in log,
                "\n".join(l for l in log.splitlines() if "WARNING" in l))
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
