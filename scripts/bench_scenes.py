"""bench_scenes.py — the bench's scenes and decks (scripts/bench.py, step 2): the bed as explicit
particles in reference_runs/bench/bench.yaml.in at the guard's dt, and the LIGGGHTS decks of it
(ours and stock) from scene_to_liggghts.py, edited for timing."""
import json
import os
import re
import shutil

import numpy as np

from scripts import engines, scene_to_liggghts
from scripts.bench_config import (BOND_MAX_GAP, BOND_STRENGTH, E_SOFT, E_STIFF, ENGINES, ETA_ROLL, fill, is_bonded,
                                  num, safe_dt, walls_yaml)


def scene_path(out, size, variant):
    return os.path.join(out, "scenes", "%s_%s.yaml" % (size, variant))


def bonds_yaml(E, r_small):
    """The bonded variants' bond type and the rule that bonds every touching pair at step 0."""
    kn = E / (2.0 * r_small)
    return ("bond_types:\n  bench: {normal_stiffness: %s, shear_stiffness: %s, tensile_strength: %s, "
            "shear_strength: %s}\nbond_rules:\n  - {type: bench, time: 0.0, max_gap: %s}\n"
            % (num(kn), num(kn / (2.0 * (1.0 + 0.3))), num(BOND_STRENGTH), num(BOND_STRENGTH), num(BOND_MAX_GAP)))


def make_scene(out, size, variant, bed_path, steps):
    """The bench scene of a variant on a bed; dt is the guard's (rounded down): for the bonded
    variants that includes the bonds' bound."""
    stiff, roll = variant.split("_")[0], variant.endswith("_roll")
    path = scene_path(out, size, variant)
    bed = np.load(bed_path)
    info = json.loads(str(bed["info"]))
    E = E_STIFF if stiff == "stiff" else E_SOFT
    kw = dict(name="bench_%s_%s" % (size, variant), variant=variant, n=len(bed["id"]),
              E=num(E), eta=num(ETA_ROLL if roll else 0.0), walls=walls_yaml(info["side"], info["height"]),
              bonds=bonds_yaml(E, float(bed["radius"].min())) if is_bonded(variant) else "")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    head = fill("bench.yaml.in", dt=1.0, steps=1, **kw)
    lines = ["  - {id: %d, material: grain, radius: %s, position: [%s, %s, %s]}\n"
             % (i, num(r), num(p[0]), num(p[1]), num(p[2]))
             for i, r, p in zip(bed["id"], bed["radius"], bed["x"])]
    with open(path, "w") as f:
        f.write(head + "".join(lines))
    dt = safe_dt(path)
    with open(path, "w") as f:
        f.write(fill("bench.yaml.in", dt=num(dt), steps=steps, **kw) + "".join(lines))
    return path, dt


def resolved_scene(scene, bed_path, d):
    """The resolved scene of `scene` (what `jdem resolve` prints) as the dict that
    scene_to_liggghts.write_deck reads, without loading the resolved YAML of every particle and
    bond: at 1M that is ~25 million YAML nodes, ~14 GB and minutes per deck.  The full resolved
    text still goes to D/resolved.yaml (the LIGGGHTS trajectory keeps it in /parameters).  Parsed
    as YAML: `jdem resolve` of the scene cut to its first particle (materials, walls, time, bond
    types: everything but the particles and bonds).  The particles are the bed's, the values the
    scene lists, in the resolved schema of that first particle; the bonds are those jdem forms at
    step 0 (/connectivity/bonds of a 1-step run), so the deck gets exactly jdem's.
    tests/engine/test_bench_tiling.py checks that the decks equal those scene_to_liggghts.py
    writes from the whole resolved YAML."""
    import h5py
    import yaml
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "resolved.yaml"), "w") as f:
        r = engines.resolve(scene, stdout=f)
    if r.returncode != 0:
        raise RuntimeError("jdem resolve %s failed:\n%s" % (scene, r.stderr))
    with open(scene) as f:
        text = f.read()
    first = text.index("\nparticles:\n") + len("\nparticles:\n")
    head = os.path.join(d, "first_particle.yaml")
    with open(head, "w") as f:
        f.write(text[:text.index("\n", first) + 1])
    r = engines.resolve(head)
    if r.returncode != 0:
        raise RuntimeError("jdem resolve %s failed:\n%s" % (head, r.stderr))
    sc = yaml.load(r.stdout, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    p0 = sc["particles"][0]
    bed = np.load(bed_path)
    sc["particles"] = [dict(p0, id=int(i), radius=float(rad), position=[float(c) for c in x])
                       for i, rad, x in zip(bed["id"], bed["radius"], bed["x"])]
    if sc.get("bond_types"):
        one = os.path.join(d, "bonds_step0.yaml")
        with open(one, "w") as f:
            f.write(re.sub(r"(?m)^  steps: \d+", "  steps: 1", text))
        h5 = os.path.join(d, "bonds_step0.h5")
        r = engines.jdem("run", one, "-o", h5, "--quiet", "--force")
        if r.returncode != 0:
            raise RuntimeError("jdem run %s failed:\n%s" % (one, r.stderr))
        names = list(sc["bond_types"])
        with h5py.File(h5, "r") as f:
            g = f["jdem/bonds"]
            step0 = g["formed_step"][...] == 0
            ids, types = g["ids"][...][step0], g["type"][...][step0]
        sc["bonds"] = [{"ids": [int(a), int(b)], "type": names[t]} for (a, b), t in zip(ids.tolist(), types.tolist())]
        for f in (one, h5, h5[:-3] + ".xdmf"):
            os.remove(f)
    return sc


def link_or_copy(src, dst):
    if os.path.exists(dst):
        os.remove(dst)
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def adapt_deck(text, engine, steps):
    """The bench's edits of a deck from scene_to_liggghts: thermo at the last step only, no
    domain split along z, and for stock LIGGGHTS its own contact count instead of our dump."""
    text = re.sub(r"(?m)^thermo\s+\d+\s*$", "thermo          %d" % steps, text)
    # the box reaches twice the bed's height (the walls' extent): never split it along z,
    # or one rank would own every particle
    text = re.sub(r"(?m)^(boundary .*)$", r"\1\nprocessors      * * 1", text, count=1)
    if engine == "liggghts":
        # stock LIGGGHTS has neither dump h5md/jdem nor the fix jdem/observables that samples for
        # it: count contacts with its own computes instead
        text = re.sub(r"(?m)^(dump |fix \S+ all jdem/observables ).*$\n", "", text)
        text = text.replace("\nrun ", "\ncompute cc all contact/atom\ncompute csum all reduce sum c_cc\n"
                            "thermo_style    custom step atoms ke c_csum\nrun ", 1)
    return text


def deck_dir(out, size, variant):
    return os.path.join(out, "decks", "%s_%s" % (size, variant))


def make_decks(out, size, variant, scene, bed_path, steps, engines=ENGINES):
    """The LIGGGHTS decks (ours and stock) of `engines` in OUT/decks/SIZE_VARIANT/ENGINE/in.bench,
    from resolved_scene() of the bench scene on its bed."""
    d = deck_dir(out, size, variant)
    wanted = [e for e in ("liggghts-jdem", "liggghts") if e in engines
              and not (e == "liggghts" and is_bonded(variant))]  # stock LIGGGHTS has no parallel bonds
    if not wanted:
        return {}
    sc = resolved_scene(scene, bed_path, d)
    decks = {}
    for engine in wanted:
        dd = os.path.join(d, engine)
        os.makedirs(dd, exist_ok=True)
        deck = os.path.join(dd, "in.bench")
        link_or_copy(os.path.join(d, "resolved.yaml"), os.path.join(dd, "resolved.yaml"))  # 270 MB at 1M bonded
        try:
            scene_to_liggghts.write_deck(sc, os.path.join(dd, "resolved.yaml"), deck, os.path.join(dd, "out.h5"),
                                         builtin=engine == "liggghts")
        except SystemExit:  # scene_to_liggghts.fail() has printed the reason
            raise RuntimeError("deck generation failed for %s (%s)" % (scene, engine))
        with open(deck) as f:
            text = adapt_deck(f.read(), engine, steps)
        with open(deck, "w") as f:
            f.write(text)
        decks[engine] = deck
    return decks
