#!/usr/bin/python3
"""Fault injection, the standalone engine `jdem`: hostile names, path traversal, signals at each
phase of `jdem run`, deep YAML, bond rules with an auto dt, misleading messages, `ulimit -v`.
Each case asserts the exit code, the message, and what is on disk.

Run:  /usr/bin/python3 tests/faults/test_jdem.py        (JDEM=path/to/jdem to override)
"""
import math
import os
import re
import signal
import subprocess
import time

import yaml

from tests.faults.faults_common import (EXIT, JDEM, ROOT, Checks, expect_files, files, finish, h5_frames,
                           h5_readable, is_root, read_only, run, scratch, signal_exit,
                           small_scene, start, tmpfs, wait_for, write_scene)

c = Checks()
VALID_NAME = ("valid: 1 to 63 characters from A-Z a-z 0-9 _ . + -, the first a letter, a digit "
              "or _")
GLASS = "{youngs_modulus: 4.8e10, poisson_ratio: 0.2, density: 2800}"


def refused(name, text, message, command="run", file_name=None, args=()):
    """`jdem COMMAND` of a scene TEXT in an empty directory D/w, no -o: exit 2 with MESSAGE (the
    scene's path and ':' before it), nothing written beside the scene nor in D (where
    out/../../NAME would escape to)."""
    d = scratch()
    work = os.path.join(d, "w")
    os.mkdir(work)
    path = write_scene(work, file_name or "scene", text)
    r = run([JDEM, command, os.path.basename(path), *args], cwd=work)
    want = f"jdem: {os.path.basename(path)}:{message}\n"
    c.check(f"{name}_exit_input", r.rc == EXIT["input"], repr(r))
    c.check(f"{name}_message", r.err == want, f"stderr {r.err!r}, want {want!r}")
    c.check(f"{name}_stdout_empty", r.out == "", f"stdout {r.out!r}")
    expect_files(c, f"{name}_nothing_written", d, ["w/" + os.path.basename(path)])


def scene_with(**fields):
    """small_scene with top-level keys replaced or added: name, case, materials, ..."""
    doc = yaml.load(small_scene(), Loader=yaml.CSafeLoader)
    doc.update(fields)
    return yaml.safe_dump(doc, sort_keys=False, width=100000)


# ---- names are data ---------------------------------------------------------------------

def hostile_names():
    # (check, top-level key, value, line, the valid prefix quoted, the character, its position)
    for name, key, value, line, prefix, what, pos in (
            ("name_newline_shell", "name", "a\nshell touch PWNED", 2, "a", "byte 0x0a", 2),
            ("name_traversal", "name", "../../esc", 2, "", "'.'", 1),
            ("name_slash", "name", "a/b", 2, "a", "'/'", 2),
            ("name_dollar", "name", "x$(id)", 2, "x", "'$'", 2),
            ("name_nul", "name", "ab\0cd", 2, "ab", "byte 0x00", 3)):
        refused(name, scene_with(**{key: value}),
                f"{line}: key '{key}': the name '{prefix}' has {what} at character {pos}, not "
                f"allowed in a name; {VALID_NAME}")
    long_name = "a" * 1000
    refused("name_1000_chars_keeps_reason", scene_with(name=long_name),
            f"2: key 'name': the name '{'a' * 32}...' is too long (1000 characters); "
            f"{VALID_NAME}")
    refused("case_space", scene_with(case="my case"),
            f"36: key 'case': the name 'my' has byte 0x20 at character 3, not allowed in a name; "
            f"{VALID_NAME.replace('63', '127')}")
    mats = yaml.load(small_scene(), Loader=yaml.CSafeLoader)["materials"]
    refused("material_semicolon", scene_with(materials={"gl;ass": mats["glass"]}),
            f"9: key 'materials': the name 'gl' has ';' at character 3, not allowed in a name; "
            f"{VALID_NAME}")
    refused("wall_hash", small_scene() + (
        "walls:\n  - {name: 'w#1', type: plane, material: glass, corners: [[-1, -1, -1], [1, -1, "
        "-1], [1, 1, -1], [-1, 1, -1]]}\n"),
        f"11: key 'walls.0.name': the name 'w' has '#' at character 2, not allowed in a name; "
        f"{VALID_NAME}")
    refused("bond_type_quote", small_scene() + (
        "bond_types:\n  \"c'x\": {normal_stiffness: 1.0, shear_stiffness: 1.0, tensile_strength: "
        "1.0, shear_strength: 1.0}\n"),
        f"11: key 'bond_types': the name 'c' has ''' at character 2, not allowed in a "
        f"name; {VALID_NAME}")
    sweep = [{"axis": "speed", "values": {"v1": {}, "v 2\nshell touch PWNED": {}}}]
    refused("sweep_value_newline", scene_with(sweep=sweep),
            f"40: key 'sweep.0.values': the name 'v' has byte 0x20 at character 2, not allowed "
            f"in a name; {VALID_NAME}", command="cases")
    refused("sweep_axis_hash", scene_with(sweep=[{"axis": "a#b", "values": {"v": {}}}]),
            f"37: key 'sweep.0.axis': the name 'a' has '#' at character 2, not allowed in a "
            f"name; {VALID_NAME}", command="cases")
    refused("default_name_from_file", small_scene().replace("name: small\n", ""),
            f"1: key 'name': the name 'my' has byte 0x20 at character 3, not allowed in a name; "
            f"{VALID_NAME} (the default name is the file name: give name:)", file_name="my scene")


def traversal():
    """A default output path is built from names only, inside out/ of the working directory."""
    d = scratch()
    work = os.path.join(d, "a", "b")
    os.makedirs(work)
    path = write_scene(work, "esc", scene_with(name="..", case="esc"))
    r = run([JDEM, "run", path, "--quiet"], cwd=work)
    c.check("traversal_dotdot_exit_input", r.rc == EXIT["input"], repr(r))
    c.check("traversal_dotdot_message", "key 'name': the name '' has '.' at character 1" in r.err,
            repr(r))
    expect_files(c, "traversal_dotdot_nothing_written", d, ["a/b/esc.yaml"])
    path = write_scene(work, "ok", scene_with(name="v1.2-a+b_c"))
    r = run([JDEM, "run", path, "--quiet"], cwd=work)
    c.check("traversal_safe_name_runs", r.rc == EXIT["ok"], repr(r))
    expect_files(c, "traversal_safe_name_output_inside_out", d,
                 ["a/b/esc.yaml", "a/b/ok.yaml", "a/b/out/v1.2-a+b_c/v1.2-a+b_c.jdem.h5",
                  "a/b/out/v1.2-a+b_c/v1.2-a+b_c.jdem.xdmf"])


# ---- limits and misleading messages ------------------------------------------------------

def deep_yaml():
    d = scratch()
    deep = write_scene(d, "deep", "[" * 250000 + "]" * 250000 + "\n")
    t0 = time.monotonic()
    r = run([JDEM, "cases", deep], timeout=300)
    elapsed = time.monotonic() - t0
    want = (f"jdem: {deep}:1: nested more than 64 levels deep; valid: at most 64 nested mappings "
            f"and sequences\n")
    c.check("deep_yaml_exit_input", r.rc == EXIT["input"], repr(r))
    c.check("deep_yaml_message", r.err == want, f"{r!r} after {elapsed:.1f} s, want {want!r}")
    # the limit's exact position: 64 levels are read (and refused for what they are)
    ok = write_scene(d, "deep64", "[" * 64 + "]" * 64 + "\n")
    r = run([JDEM, "cases", ok])
    c.check("depth_64_is_read", "expected a mapping at the top level, got a sequence" in r.err,
            repr(r))
    expect_files(c, "deep_yaml_nothing_written", d, ["deep.yaml", "deep64.yaml"])


def cases_validates():
    # the list of valid top-level keys is the one the scene reader's own malformed-scene test expects
    with open(os.path.join(ROOT, "tests", "scenes", "bad", "unknown_top_key.expect")) as f:
        valid = f.read().strip().split("unknown key; valid: ", 1)[1]
    refused("cases_unknown_key", small_scene() + "bogus: 1\n",
            "10: key 'bogus': unknown key; valid: " + valid, command="cases")


def cylinder_radius():
    text = small_scene() + (
        "walls:\n  - {name: drum, type: cylinder, material: glass, axis: [[0, 0, -1], [0, 0, 1]], "
        "radius: 1.0e10, side: inside}\n")
    refused("cylinder_radius_1e10", text,
            "11: key 'walls.0.radius': the radius 1e+10 m is more than 1e+09 times the axis "
            "length 2 m; valid: a radius of at most 2e+09 m for this axis (or a longer axis)")


def huge_velocity():
    """v = 1e200 m/s: the state is finite but its energy is not."""
    d = scratch()
    text = small_scene().replace("velocity: [1, 0, 0]", "velocity: [1.0e200, 0, 0]", 1)
    path = write_scene(d, "fast", text)
    out = os.path.join(d, "fast.h5")
    r = run([JDEM, "run", path, "-o", out, "--quiet", "--force"])
    c.check("velocity_1e200_exit_failed_run", r.rc == EXIT["watchdog"], repr(r))
    c.check("velocity_1e200_message_names_the_energy", "out of memory" not in r.err and
            re.search(r"^jdem: watchdog: step \d+: .*total energy inf J", r.err, re.M), repr(r))
    c.check("velocity_1e200_part_readable", h5_readable(out + ".part") is None,
            h5_readable(out + ".part"))


def parse_out_of_memory():
    """A scene whose tree does not fit under `ulimit -v`: out of memory, not a parse error."""
    d = scratch()
    lines = "".join(f"  - {{id: {k}, material: glass, radius: 0.001, position: [{k * 0.003}, 0, "
                    f"0]}}\n" for k in range(1, 200001))
    path = write_scene(d, "big", small_scene().split("particles:")[0] + "particles:\n" + lines)
    r = run([JDEM, "cases", path], mem_bytes=200 << 20)
    want = f"jdem: {path}: out of memory reading the scene\n"
    c.check("parse_oom_exit_memory", r.rc == EXIT["memory"], repr(r))
    c.check("parse_oom_message", r.err == want, f"{r!r}, want {want!r}")
    expect_files(c, "parse_oom_nothing_written", d, ["big.yaml"])
    os.unlink(path)


def run_under_ulimit():
    """`jdem run` of 144k spheres under `ulimit -v` from 120 to 400 MB: at each limit a class
    exit code (0, 3 or 5) and no crash, OUT.h5 exactly when the exit is 0, a message naming the
    cause otherwise, and a .part only if readable or said lost.  The sweep must see both an
    out-of-memory refusal and a complete run.  (A failure inside HDF5 needs the io branch.)"""
    d = scratch()
    path = write_scene(d, "lattice", small_scene(steps=20).split("particles:")[0] +
                       "generate:\n  - lattice: {material: glass, radius: 0.001, spacing: 0.0021, "
                       "origin: [0, 0, 0], counts: [60, 60, 40]}\n")
    out = os.path.join(d, "lat.h5")
    bad, seen = [], set()
    for mb in range(120, 401, 40):
        r = run([JDEM, "run", path, "-o", out, "--quiet", "--force"], mem_bytes=mb << 20)
        seen.add(r.rc)
        left = [f for f in files(d) if f != "lattice.yaml"]
        said = re.search(r"^jdem: .*(out of memory|memory allocation|cannot)", r.err, re.M)
        if r.rc == EXIT["ok"]:
            ok = h5_readable(out) is None and not any(f.endswith(".part") for f in left)
        elif r.rc in (EXIT["memory"], EXIT["io"]):
            ok = said and "lat.h5" not in left and (
                "lat.h5.part" not in left or h5_readable(out + ".part") is None or
                "nothing" in r.err)
        else:
            ok = False
        if not ok:
            bad.append(f"{mb} MB: {r!r}, files {left}")
        for f in left:
            os.unlink(os.path.join(d, f))
    c.check("ulimit_v_every_limit_clean", not bad, "; ".join(bad))
    c.check("ulimit_v_sweep_sees_oom_and_success", {EXIT["memory"], EXIT["ok"]} <= seen,
            f"exit codes seen {sorted(seen)}")


# ---- bond rules with dt: auto -------------------------------------------------------------

BOND_SCENE = """\
jdem_scene: 1
name: rules
time: {{dt: {dt}, end_time: 2.0e-5}}
output: {{every: 50}}
materials:
  clay: {{youngs_modulus: 1.0e8, poisson_ratio: 0.3, density: 2600}}
particles:
  - {{id: 1, material: clay, radius: 0.001, position: [0, 0, 0]}}
  - {{id: 2, material: clay, radius: 0.001, position: [0.002, 0, 0]}}
bond_types:
  cement: {{normal_stiffness: 2.0e12, shear_stiffness: 1.0e12, tensile_strength: 5.0e6,
           shear_strength: 5.0e6}}
bond_rules:
  - {{type: cement, time: 1.0e-5}}
  - {{type: cement, step: 2}}
"""


def bond_rules_dt_auto():
    d = scratch()
    path = write_scene(d, "rules", BOND_SCENE.format(dt="auto"))
    r = run([JDEM, "resolve", path])
    if not c.check("bond_rules_dt_auto_resolves", r.rc == 0, repr(r)):
        return
    res = yaml.load(r.out, Loader=yaml.CSafeLoader)
    dt = res["time"]["dt"]
    steps = [rule["step"] for rule in res["bond_rules"]]
    want = sorted([2, math.ceil(1.0e-5 / dt - 1e-9)])
    c.check("bond_rules_dt_auto_steps", steps == want, f"steps {steps}, want {want} (dt {dt!r})")
    # the same scene with that dt written out resolves to the same rules
    fixed = write_scene(d, "fixed", BOND_SCENE.format(dt=repr(dt)))
    rf = run([JDEM, "resolve", fixed])
    c.check("bond_rules_dt_auto_equals_explicit_dt",
            rf.rc == 0 and yaml.load(rf.out, Loader=yaml.CSafeLoader)["bond_rules"] == res["bond_rules"], repr(rf))
    out = os.path.join(d, "rules.h5")
    r = run([JDEM, "run", path, "-o", out, "--quiet"])
    c.check("bond_rules_dt_auto_runs", r.rc == 0 and h5_readable(out) is None, repr(r))


# ---- signals at each phase of `jdem run` --------------------------------------------------

def big_scene(d):
    """A scene whose reading takes a while (600k explicit particles in a line)."""
    lines = "".join(f"  - {{id: {k}, material: glass, radius: 0.01, position: [{k * 0.03}, 0, "
                    f"0]}}\n" for k in range(1, 600001))
    return write_scene(d, "big", small_scene().split("particles:")[0] + "particles:\n" + lines)


def signal_while_reading():
    d = scratch()
    path = big_scene(d)
    out = os.path.join(d, "big.h5")
    for sig, word in ((signal.SIGTERM, "terminated"), (signal.SIGINT, "interrupted")):
        p = start([JDEM, "run", path, "-o", out, "--quiet"])
        time.sleep(0.5)
        p.send_signal(sig)
        r = finish(p, timeout=300)
        name = f"signal_{sig.name}_during_setup"
        want = f"jdem: {word} ({sig.name}) during set-up; nothing was written\n"
        c.check(f"{name}_exit", r.rc == signal_exit(sig), repr(r))
        c.check(f"{name}_message", r.err == want, f"{r!r}, want {want!r}")
        expect_files(c, f"{name}_nothing_written", d, ["big.yaml"])
    os.unlink(path)  # 30 MB


def signal_mid_run():
    d = scratch()
    path = write_scene(d, "long", small_scene(name="long", steps=2000000000, every=100000))
    out = os.path.join(d, "long.h5")
    p = start([JDEM, "run", path, "-o", out, "--quiet"])
    wait_for(lambda: os.path.exists(out + ".part"), 30)
    time.sleep(0.5)
    p.send_signal(signal.SIGTERM)
    r = finish(p)
    c.check("signal_mid_run_exit", r.rc == signal_exit(signal.SIGTERM), repr(r))
    m = re.fullmatch(rf"jdem: terminated \(SIGTERM\) at step (\d+); the trajectory up to step "
                     rf"(\d+) is kept, closed, as {re.escape(out)}\.part\n", r.err)
    c.check("signal_mid_run_message", m is not None, repr(r))
    c.check("signal_mid_run_part_readable", h5_readable(out + ".part") is None,
            h5_readable(out + ".part"))
    if m:
        c.check("signal_mid_run_last_frame", h5_frames(out + ".part")[-1] == int(m.group(1)),
                f"frames {h5_frames(out + '.part')[-3:]}, stopped at {m.group(1)}")
    expect_files(c, "signal_mid_run_files", d, ["long.yaml", "long.h5.part", "long.xdmf.part"]
                 if os.path.exists(out[:-3] + ".xdmf.part") else ["long.yaml", "long.h5.part"])


def signal_sweep():
    """SIGTERM at delays spread over a whole short run, from the process' start to the final
    write: each outcome is a complete run (exit 0, OUT.h5, no .part), a stopped one (exit 143, a
    readable OUT.h5.part or, during set-up, nothing), or, before main() runs, the default action
    with nothing on disk; never a crash or a half-written final file."""
    d = scratch()
    path = write_scene(d, "short", small_scene(name="short", steps=20000, every=2000))
    out = os.path.join(d, "short.h5")
    t0 = time.monotonic()
    r = run([JDEM, "run", path, "-o", out, "--quiet"])
    whole = time.monotonic() - t0
    if not c.check("signal_sweep_reference_run", r.rc == 0, repr(r)):
        return
    bad, outcomes = [], {}
    for k in range(32):
        for f in files(d):
            if f != "short.yaml":
                os.unlink(os.path.join(d, f))
        p = start([JDEM, "run", path, "-o", out, "--quiet"])
        time.sleep(whole * k / 24)
        try:
            p.send_signal(signal.SIGTERM)
        except ProcessLookupError:
            pass
        r = finish(p)
        outcomes[r.rc] = outcomes.get(r.rc, 0) + 1
        left = [f for f in files(d) if f != "short.yaml"]
        if r.rc == -signal.SIGTERM:  # before main() installed its handlers
            ok = not left
        elif r.rc == 0:
            ok = os.path.exists(out) and h5_readable(out) is None and not any(
                f.endswith(".part") for f in left)
        elif r.rc == signal_exit(signal.SIGTERM):
            ok = not os.path.exists(out) and (
                ("during set-up; nothing was written" in r.err and not left) or
                ("is kept, closed, as" in r.err and h5_readable(out + ".part") is None))
        else:
            ok = False
        if not ok:
            bad.append(f"delay {k}: {r!r}, files {left}")
    c.check("signal_sweep_every_outcome_complete_or_kept", not bad,
            f"{'; '.join(bad)} (outcomes by exit code {outcomes})")
    print(f"# signal sweep over {whole:.2f} s runs: outcomes by exit code {outcomes}")


# ---- disk full and read-only output (the writer's part needs the io branch) --------------------

def disk_faults():
    """The I/O class (exit 3) for a full disk at creation and mid-run, and a read-only mount:
    a message naming the cause, nothing under the final name, and a .part left only if it is
    readable or the message says that nothing could be kept."""
    d = scratch()
    small = write_scene(d, "small", small_scene())
    longer = write_scene(d, "longer", small_scene(name="longer", steps=200000, every=10))
    for name, size, scene in (("disk_full_at_creation", "64k", small),
                              ("disk_full_mid_run", "1m", longer)):
        with tmpfs(size) as mnt:
            out = os.path.join(mnt, "a.h5")
            r = run([JDEM, "run", scene, "-o", out, "--quiet"])
            c.check(f"{name}_exit_io", r.rc == EXIT["io"], repr(r))
            c.check(f"{name}_message", "No space left on device" in r.err, repr(r))
            left = files(mnt)
            c.check(f"{name}_no_final_file", "a.h5" not in left, f"files {left}")
            if "a.h5.part" in left:
                why = h5_readable(out + ".part")
                c.check(f"{name}_part_readable_or_said_lost", why is None or "nothing" in r.err,
                        f"{why}; {r!r}")
    ro_dir = scratch()
    with read_only(ro_dir) as ro:
        out = os.path.join(ro, "a.h5")
        r = run([JDEM, "run", small, "-o", out, "--quiet"])
        c.check("read_only_exit_io", r.rc == EXIT["io"], repr(r))
        c.check("read_only_message", re.fullmatch(rf"jdem: .*{re.escape(out)}.*Read-only file "
                                                  rf"system.*\n", r.err, re.S), repr(r))
    expect_files(c, "read_only_nothing_written", ro_dir, [])


# ---- exit codes by class -------------------------------------------------------------------

def exit_codes():
    d = scratch()
    wd = write_scene(d, "blowup", small_scene(name="blowup").replace("velocity: [1, 0, 0]",
                     "velocity: [1.0e3, 0, 0]", 1) + "watchdog: {max_overlap_fraction: 0.01}\n")
    r = run([JDEM, "run", wd, "-o", os.path.join(d, "w.h5"), "--quiet", "--force"])
    c.check("exit_watchdog", r.rc == EXIT["watchdog"] and "watchdog" in r.err, repr(r))
    r = run([JDEM, "run", "--bogus", wd])
    c.check("exit_usage_is_input", r.rc == EXIT["input"] and
            r.err == "jdem: unknown option: --bogus\nTry 'jdem --help'.\n", repr(r))
    r = run([JDEM, "run", os.path.join(d, "missing.yaml")])
    c.check("exit_missing_scene_is_input", r.rc == EXIT["input"] and
            r.err == f"jdem: {d}/missing.yaml: cannot open: No such file or directory\n", repr(r))
    r = run([JDEM, "cases", d])
    c.check("exit_scene_is_directory", r.rc == EXIT["input"] and
            r.err == f"jdem: {d}: cannot read: not a regular file; valid: a YAML file\n", repr(r))
    blocker = os.path.join(d, "file")
    open(blocker, "w").close()
    small = write_scene(d, "small", small_scene())
    r = run([JDEM, "run", small, "-o", os.path.join(blocker, "sub", "x.h5"), "--quiet"])
    c.check("exit_output_dir_cannot_be_made_is_io", r.rc == EXIT["io"] and
            r.err == f"jdem: cannot create directory {blocker}/sub: Not a directory\n", repr(r))
    with open("/dev/full", "w") as full:
        p = subprocess.run([JDEM, "resolve", small], stdout=full, stderr=subprocess.PIPE, text=True)
    c.check("exit_resolve_to_full_disk_is_io", p.returncode == EXIT["io"] and
            p.stderr == "jdem: cannot write the resolved scene\n",
            f"exit {p.returncode}, {p.stderr!r}")
    h = run([JDEM, "--help"])
    c.check("help_lists_exit_codes", all(f"  {k}  " in h.out or f"  {k}        " in h.out
                                         for k in ("0", "1", "2", "3", "4", "5")) and
            "128 + N" in h.out, h.out[-900:])


hostile_names()
traversal()
deep_yaml()
cases_validates()
cylinder_radius()
huge_velocity()
bond_rules_dt_auto()
exit_codes()
signal_while_reading()
signal_mid_run()
signal_sweep()
parse_out_of_memory()
run_under_ulimit()
if is_root():
    disk_faults()
else:
    c.skip("disk_faults", "mounting a tmpfs or a read-only bind needs root")
c.exit()
