"""jdem checkpoints (docs/scenes.md "Checkpoints"): a run killed with SIGKILL after a checkpoint
and resumed from it equals the uninterrupted run bit for bit (every dataset of the trajectory,
tests/checkpoint/compare_h5.py), on 1 and 2 threads, for a settling bed with walls, friction
and rolling, a servo compression, an inlet stream, a bonded beam and an inlet of bonded blocks
(the checkpoint between two copies' insertions), a bed in a turning meshed drum and spheres
on a meshed conveyor (the mesh's moved corners, its contact history and candidates), spheres
leaving the domain (the shrinking set, its bonds and loads), spheres raining onto a bed (each
particle's half skin), a sparse rain (the partial builds' reference positions), the inlet
stream again just before an insertion whose build is full (every half skin renewed), cohesive
MEPA contacts (their plastic overlaps), a floor that has vanished (docs/scenes.md "A wall that
vanishes"); SIGTERM
writes a checkpoint and exits 143; bad checkpoints are refused with their messages; a failed
checkpoint write keeps the previous checkpoint and stops the run (exit 3)."""
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py

from tests.checkpoint.compare_h5 import differences
from tests.mesh.test_mesh_engines import floor_grid, particle
from tests.mesh.test_mesh_motion import CENTRE, drum, write_case

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

JDEM = os.environ.get("JDEM", os.path.join(ROOT, "build", "jdem"))
FAILED = []

CASES = [  # scene, case, checkpoint every N steps
    ("tests/engine/scenes/lattice_floor.yaml", None, 15000),
    ("tests/engine/scenes/servo_columns.yaml", None, 500),
    ("tests/checkpoint/scenes/inlet_stream.yaml", None, None),
    ("reference_runs/stability/bonded_beam.yaml", "tip_load", 20000),
    # a checkpoint between the two copies' block insertions (steps 1330 and 2730)
    ("tests/inlet/bonded_section.yaml", None, 2500),
    # a checkpoint between deletions outside the domain (steps 47, 124 and 200)
    ("tests/engine/scenes/domain_exit.yaml", None, 100),
    # a checkpoint mid-rain, the falling spheres' half skins 4.5 x the bed's
    ("tests/engine/scenes/shower.yaml", None, 1100),
    # a checkpoint between partial neighbour builds (each particle's reference position)
    ("tests/engine/scenes/drizzle.yaml", None, 2100),
    # a checkpoint just before an insertion whose build is full because most particles moved
    # (step 64000): every half skin renewed, the inserted particle's too
    ("tests/checkpoint/scenes/inlet_stream.yaml", None, 63162),
    # MEPA's contacts mid-hysteresis: their plastic overlaps in the checkpoint's history
    ("tests/liggghts/scenes/mpi_mepa_cohesive.yaml", None, 2500),
    # a checkpoint after a wall vanished (step 15000): resumed, it stays gone
    ("tests/liggghts/scenes/mpi_wall_vanishes.yaml", None, 17000),
]


def mesh_cases(d):
    """(scene, case, every) of two mesh scenes written into d: 18 spheres, touching each other,
    dropped into a drum that turns about an axis off the origin, checkpointed once they lie on
    its wall; 9 spheres on a still meshed conveyor, checkpointed while they speed up."""
    R = 0.004
    bed = [particle((CENTRE[0] + 2.2 * R * (i - 1), CENTRE[1] + 2.2 * R * (j - 0.5),
                     CENTRE[2] - 0.03 + 2.05 * R * k), r=R)
           for i in range(3) for j in range(2) for k in range(3)]
    turning = "rotation: {origin: [%r, %r, %r], axis: [0, 1, 0], period: -0.8}" % CENTRE
    # resting on the belt with Hertz's static overlap (tests/mesh/test_mesh_motion.check_belt),
    # so that they keep their contacts while the belt speeds them up
    r, m = 0.005, 4.0 / 3.0 * math.pi * 0.005 ** 3 * 2500.0
    delta = (m * 9.81 / (4.0 / 3.0 * 1.0e7 / (1.0 - 0.09) * math.sqrt(r))) ** (2.0 / 3.0)
    belt = [particle((0.012 * (i - 1), 0.012 * (j - 1), r - delta), r=r)
            for i in range(3) for j in range(3)]
    return [(write_case(d, "mesh_drum", drum(32, 0.05, 0.06, CENTRE), bed, turning, 40000), None, 12000),
            (write_case(d, "mesh_belt", floor_grid(8, 2.0 ** -3), belt, "surface_velocity: [0.1, 0.05, 0]",
                        20000), None, 6000)]


def check(name, ok, detail=""):
    print(f"{'PASS' if ok else 'FAIL'} {name}{'' if ok else ': ' + detail}", flush=True)
    if not ok:
        FAILED.append(name)


def jdem(scene, out, *extra, case=None, threads=1):
    cmd = [JDEM, "run", os.path.join(ROOT, scene), "-o", out, "--quiet", "--threads", str(threads)]
    return cmd + (["--case", case] if case else []) + list(extra)


def steps_of(scene, case):
    text = subprocess.run([JDEM, "resolve", os.path.join(ROOT, scene)] + (["--case", case] if case else []),
                          capture_output=True, text=True, check=True).stdout
    for line in text.splitlines():
        if line.strip().startswith("steps:"):
            return int(line.split(":")[1])
    raise RuntimeError("no steps")


def wait_for(path, proc, limit=600):
    """Wait until path exists while proc runs; the cases leave at least three quarters of their
    run after the first checkpoint, so a 10 ms poll sees it before the run ends."""
    t0 = time.time()
    while not os.path.exists(path):
        if proc.poll() is not None or time.time() - t0 > limit:
            return False
        time.sleep(0.01)
    return True


def killed_and_resumed(d, scene, case, every, threads):
    tag = f"{os.path.basename(scene)[:-5]} {threads} thread(s)"
    if tag.startswith("scene "):   # a generated case: its folder names it
        tag = os.path.basename(os.path.dirname(scene)) + tag[5:]
    a, b = os.path.join(d, "a.h5"), os.path.join(d, "b.h5")
    ck = os.path.join(d, "b.ckpt.h5")
    every = every or steps_of(scene, case) // 4
    subprocess.run(jdem(scene, a, case=case, threads=threads), check=True)
    p = subprocess.Popen(jdem(scene, b, "--checkpoint-every", str(every), case=case, threads=threads))
    got = wait_for(ck, p)
    p.send_signal(signal.SIGKILL)
    p.wait()
    check(f"{tag}: a checkpoint was written before the kill", got and p.returncode == -9,
          f"exit {p.returncode}")
    r = subprocess.run(jdem(scene, b, "--checkpoint-every", str(every), "--resume", ck, case=case,
                            threads=threads), capture_output=True, text=True)
    check(f"{tag}: the resumed run completes", r.returncode == 0, r.stderr[-400:])
    if r.returncode == 0:
        diffs, n = differences(a, b)
        check(f"{tag}: resumed == uninterrupted, bit for bit ({n} datasets)", not diffs and n > 10,
              "; ".join(diffs[:5]))
        check(f"{tag}: the complete run removed its checkpoint", not os.path.exists(ck))


def sigterm(d):
    scene, out = CASES[0][0], os.path.join(d, "t.h5")
    ck = os.path.join(d, "t.ckpt.h5")
    every = str(steps_of(scene, None) // 4)  # the first checkpoint says the run is under way
    p = subprocess.Popen(jdem(scene, out, "--checkpoint", ck, "--checkpoint-every", every),
                         stderr=subprocess.PIPE, text=True)
    wait_for(ck, p)
    time.sleep(0.1)  # past the periodic checkpoint's step, so that SIGTERM's is a new one
    p.send_signal(signal.SIGTERM)
    err = p.communicate()[1]
    check("SIGTERM: exit status 143", p.returncode == 143, f"exit {p.returncode}: {err[-300:]}")
    m = re.search(r"checkpoint of step (\d+) written to (\S+); continue with --resume (\S+)", err)
    check("SIGTERM: a checkpoint of the stopping step is written and named",
          m is not None and int(m.group(1)) > int(every) and m.group(2) == m.group(3) == ck
          and os.path.exists(ck), err[-300:])
    r = subprocess.run(jdem(scene, out, "--checkpoint-every", every, "--resume", ck),
                       capture_output=True, text=True)
    a = os.path.join(d, "ref.h5")
    subprocess.run(jdem(scene, a), check=True)
    diffs, _ = differences(a, out) if r.returncode == 0 else (["resume failed " + r.stderr], 0)
    check("SIGTERM: the resumed run equals the uninterrupted one", not diffs, "; ".join(diffs[:3]))
    creators(out, a)
    return ck


def creators(resumed, uninterrupted):
    """The creator version is `jdem --version`'s (the release and the source commit); a resumed
    trajectory names the binary that computed the frames it copied ("continues")."""
    version = subprocess.run([JDEM, "--version"], capture_output=True, text=True).stdout.split()[-1]
    with h5py.File(resumed, "r") as r, h5py.File(uninterrupted, "r") as u:
        attrs = {k: (v.decode() if isinstance(v, bytes) else str(v))
                 for k, v in r["h5md/creator"].attrs.items()}
        plain = "continues" in u["h5md/creator"].attrs
    check("SIGTERM: the creator names the source commit", attrs.get("version") == version
          and "+" in version, f"{attrs} against jdem --version {version}")
    check("SIGTERM: the resumed trajectory names the binary of its first part",
          attrs.get("continues") == version and not plain, f"{attrs}")


def refused(name, cmd, message, status=2):
    r = subprocess.run(cmd, capture_output=True, text=True)
    check(f"{name}: exit {status}", r.returncode == status, f"exit {r.returncode}")
    check(f"{name}: message", message in r.stderr, f"want {message!r}, got {r.stderr[-400:]!r}")


def bad_checkpoints(d):
    scene, out = CASES[0][0], os.path.join(d, "bad.h5")
    ck = os.path.join(d, "good.ckpt.h5")
    subprocess.run(jdem(scene, out, "--checkpoint-every", "10000") + ["--quiet"], check=True)
    p = subprocess.Popen(jdem(scene, out, "--checkpoint", ck, "--checkpoint-every", "10000"))
    wait_for(ck, p)
    p.kill()
    p.wait()
    missing = os.path.join(d, "none.ckpt.h5")
    refused("missing checkpoint", jdem(scene, out, "--resume", missing),
            f"jdem: cannot resume: checkpoint '{missing}': No such file or directory; valid: a "
            "checkpoint written by 'jdem run --checkpoint' for this scene")
    half = os.path.join(d, "half.ckpt.h5")
    with open(ck, "rb") as f, open(half, "wb") as g:
        g.write(f.read()[: os.path.getsize(ck) // 2])
    refused("truncated checkpoint", jdem(scene, out, "--resume", half),
            f"jdem: cannot resume: '{half}' is not a readable HDF5 file (truncated or corrupt); "
            "valid: a checkpoint written by 'jdem run --checkpoint' for this scene")
    changed = os.path.join(d, "changed.ckpt.h5")
    shutil.copy(ck, changed)
    with h5py.File(changed, "r+") as f:
        f["particles/x"][0] += 1e-9
    refused("corrupt checkpoint", jdem(scene, out, "--resume", changed),
            f"jdem: cannot resume: checkpoint '{changed}' is corrupt (its values do not match "
            "their digest)")
    other = CASES[1][0]
    refused("checkpoint of another scene", jdem(other, out, "--resume", ck),
            f"jdem: cannot resume: checkpoint '{ck}' is of another scene (scene 'lattice_floor', "
            "case 'lattice_floor'")
    refused("checkpoint of another thread count", jdem(scene, out, "--resume", ck, threads=2),
            f"jdem: cannot resume: checkpoint '{ck}' was written with --threads 1, this run has 2; "
            "valid: --threads 1")


def failed_write(d):
    """The next checkpoint cannot be written (a directory stands where its temporary file goes,
    which stops root as well as a user): the run stops with exit 3 and keeps the previous one."""
    scene = CASES[0][0]
    ck = os.path.join(d, "run.ckpt.h5")
    out = os.path.join(d, "w.h5")
    every = str(steps_of(scene, None) // 4)
    p = subprocess.Popen(jdem(scene, out, "--checkpoint", ck, "--checkpoint-every", every),
                         stderr=subprocess.PIPE, text=True)
    wait_for(ck, p)
    os.kill(p.pid, signal.SIGSTOP)  # no checkpoint is being written while the way is blocked
    while os.path.exists(ck + ".tmp"):
        os.kill(p.pid, signal.SIGCONT)
        time.sleep(0.001)
        os.kill(p.pid, signal.SIGSTOP)
    os.mkdir(ck + ".tmp")
    before = open(ck, "rb").read()
    os.kill(p.pid, signal.SIGCONT)
    err = p.communicate()[1]
    check("failed checkpoint write: exit 3", p.returncode == 3, f"exit {p.returncode}: {err[-300:]}")
    check("failed checkpoint write: message", "checkpoint at step" in err and
          "failed:" in err and f"the previous checkpoint '{ck}' is unchanged" in err, err[-400:])
    after = open(ck, "rb").read() if os.path.exists(ck) else b""
    check("failed checkpoint write: the previous checkpoint is intact", after == before)
    check("failed checkpoint write: the trajectory is kept as OUT.part, not under its final name",
          os.path.exists(out + ".part") and not os.path.exists(out))


def main():
    with tempfile.TemporaryDirectory() as d:
        for scene, case, every in CASES + mesh_cases(d):
            for threads in (1, 2):
                sub = tempfile.mkdtemp(dir=d)
                killed_and_resumed(sub, scene, case, every, threads)
        sigterm(tempfile.mkdtemp(dir=d))
        bad_checkpoints(tempfile.mkdtemp(dir=d))
        failed_write(tempfile.mkdtemp(dir=d))
    sys.exit(1 if FAILED else 0)


if __name__ == "__main__":
    main()
