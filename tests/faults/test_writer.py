#!/usr/bin/python3
"""Faults at the trajectory writer (io/h5md*.c), in both engines: a disk that fills at creation,
mid-run and at the final write (a small tmpfs), a read-only output directory, symbolic links at
OUT.h5.part and OUT.xdmf.part, two runs on one output path, an output path that is a directory,
and an address-space limit (`ulimit -v`).  Each case asserts the exit code, the message and the
files left on disk.  jdem runs directly; liggghts-jdem through scripts/liggghts_run.py.
"""
import os
import signal
import sys

from tests.faults.faults_common import (EXIT, JDEM, PY, ROOT, Checks, NotRoot, files, h5_readable,  # noqa: E402
                           read_only, run, scratch, small_scene, start, finish, tmpfs,
                           wait_for, wait_for_file, write_scene)

LIGGGHTS_RUN = os.path.join(ROOT, "scripts", "liggghts_run.py")


def jdem(scene, out, **kw):
    return run([JDEM, "run", "--quiet", scene, "-o", out], **kw)


def case_symlinks(c):
    d = scratch()
    scene = write_scene(d, "small", small_scene())
    victim = os.path.join(d, "victim.txt")
    for link in ("b.h5.part", "b.xdmf.part"):
        with open(victim, "w") as f:
            f.write("keep")
        for name in ("b.h5.part", "b.xdmf.part"):
            if os.path.lexists(os.path.join(d, name)):
                os.remove(os.path.join(d, name))
        os.symlink(victim, os.path.join(d, link))
        r = jdem(scene, os.path.join(d, "b.h5"))
        with open(victim) as f:
            kept = f.read() == "keep"
        c.check(f"jdem: symlink at {link}: target untouched", kept, repr(r))
        if link == "b.h5.part":
            c.check("jdem: symlink at b.h5.part: refused, I/O exit code",
                    r.rc == EXIT["io"] and "is a symbolic link; a trajectory is never written "
                    "through one" in r.err, repr(r))
        else:
            # the sidecar's .part is replaced (the link removed, never followed) and the run ends
            c.check("jdem: symlink at b.xdmf.part: replaced, run complete",
                    r.rc == 0 and not os.path.islink(os.path.join(d, "b.xdmf.part"))
                    and os.path.exists(os.path.join(d, "b.xdmf")), repr(r))


def case_concurrent(c):
    d = scratch()
    long_scene = write_scene(d, "long", small_scene(name="long", steps=3000000, every=100000))
    short = write_scene(d, "short", small_scene())
    out = os.path.join(d, "c.h5")
    first = start([JDEM, "run", "--quiet", long_scene, "-o", out])
    if not wait_for_file(out + ".part", 30):
        c.check("jdem: two runs on one path: first run started", False, "no c.h5.part")
        first.kill()
        return
    # the file exists (locked, empty) before HDF5 writes its header: wait for the header
    if not wait_for(lambda: os.path.getsize(out + ".part") > 0, 30):
        c.check("jdem: two runs on one path: first run wrote its header", False, "c.h5.part empty")
        first.kill()
        return
    size_before = os.path.getsize(out + ".part")
    r = jdem(short, out)
    c.check("jdem: two runs on one path: second refused (locked), I/O exit code",
            r.rc == EXIT["io"] and "is being written by another run" in r.err, repr(r))
    # the live file is locked against readers too; not truncated is what can be seen now
    size_after = os.path.getsize(out + ".part")
    c.check("jdem: two runs on one path: first run's file not truncated",
            size_after >= size_before > 0, f"{size_before} -> {size_after} bytes")
    first.send_signal(signal.SIGINT)
    r1 = finish(first)
    c.check("jdem: two runs on one path: first run stops cleanly, its frames kept",
            r1.rc == 128 + signal.SIGINT and h5_readable(out + ".part") is None, repr(r1))


def case_directory(c):
    d = scratch()
    scene = write_scene(d, "small", small_scene())
    target = os.path.join(d, "out")
    os.mkdir(target)
    r = jdem(scene, target)
    c.check("jdem: output path a directory: refused, I/O exit code",
            r.rc == EXIT["io"] and f"output path '{target}' is a directory" in r.err, repr(r))
    c.check("jdem: output path a directory: nothing written", files(d) == ["small.yaml"],
            str(files(d)))


def case_disk_full(c, engine):
    """A tmpfs too small for the run: the run fails with an I/O exit code, no crash; what the
    message names is on disk and readable, or the message says nothing could be kept."""
    for size, steps, label in (("64k", 2000, "at creation"), ("160k", 40000, "mid-run")):
        d = scratch()
        scene = write_scene(d, "small", small_scene(steps=steps, every=10))
        try:
            with tmpfs(size) as mnt:
                out = os.path.join(mnt, "a.h5")
                if engine == "jdem":
                    r = jdem(scene, out)
                else:
                    r = run([PY, LIGGGHTS_RUN, scene, "-o", out], timeout=300)
                left = files(mnt)
                part_ok = h5_readable(out + ".part") if "a.h5.part" in left else "absent"
        except NotRoot as e:
            c.skip(f"{engine}: disk full {label}", str(e))
            return
        c.check(f"{engine}: disk full {label}: no crash (exit {r.rc})",
                r.rc not in (-signal.SIGSEGV, 139, -signal.SIGABRT, 134) and r.rc != 0, repr(r))
        if engine == "jdem":
            c.check(f"{engine}: disk full {label}: I/O exit code", r.rc == EXIT["io"], repr(r))
        # jdem names the .part it keeps; liggghts-jdem's log names the file that failed
        named = ("the partial trajectory is in" in r.err if engine == "jdem"
                 else "a.h5.part" in r.err)
        c.check(f"{engine}: disk full {label}: the named .part is readable, or nothing kept",
                (named and "a.h5.part" in left and part_ok is None) or
                ("a.h5.part" not in left and "nothing could be kept" in r.err),
                f"{r.err.strip()[-300:]!r}; files {left}; .part: {part_ok}")
        c.check(f"{engine}: disk full {label}: no a.h5 or sidecar under the final names",
                "a.h5" not in left and "a.xdmf" not in left, str(left))


def fill_to(directory, free_bytes):
    """A filler file in DIRECTORY that leaves exactly FREE_BYTES (a multiple of its block size)."""
    st = os.statvfs(directory)
    with open(os.path.join(directory, "filler"), "wb") as f:
        f.write(b"\0" * (st.f_bavail * st.f_frsize - free_bytes))


def pages(nbytes, size=4096):
    return -(-nbytes // size) * size


def liggghts_deck(scene, out, deck_dir):
    """The deck of SCENE writing OUT, in DECK_DIR (outside the tmpfs, so that the log and the
    deck take none of its space); the command that runs it there."""
    resolved = os.path.join(deck_dir, "resolved.yaml")
    r = run([JDEM, "resolve", scene])
    with open(resolved, "w") as f:
        f.write(r.out)
    r = run([PY, os.path.join(ROOT, "scripts", "scene_to_liggghts.py"), resolved, "-o",
             os.path.join(deck_dir, "in.jdem"), "--trajectory", out])
    if r.rc != 0:
        raise RuntimeError(repr(r))
    return [os.path.join(ROOT, "build", "liggghts-jdem"), "-in", "in.jdem", "-log", "log.lammps",
            "-screen", "none"]


def run_engine(engine, scene, out, before_run=lambda: None):
    """SCENE to OUT in ENGINE; liggghts-jdem runs its deck outside OUT's directory."""
    if engine == "jdem":
        before_run()
        return jdem(scene, out)
    deck_dir = scratch()
    cmd = liggghts_deck(scene, out, deck_dir)
    before_run()
    return run(cmd, cwd=deck_dir, timeout=300)


def case_disk_full_at_final_write(c, engine):
    """The disk fills at the final write: the new trajectory fits, its sidecar does not.  A tmpfs
    holding an earlier result (a shorter run) under the final names is filled to exactly the
    new .h5's size in pages (measured from the same run on a normal disk): the run fails with
    the I/O reason, the earlier a.h5 and a.xdmf are byte-identical, the new run is complete and
    readable in a.h5.part (the message says so), and no sidecar .part is left."""
    d = scratch()
    scene = write_scene(d, "small", small_scene(steps=2000, every=10))
    earlier = write_scene(d, "earlier", small_scene(name="earlier", steps=1000, every=10))
    reference = os.path.join(d, "reference", "a.h5")
    os.mkdir(os.path.dirname(reference))
    r = run_engine(engine, scene, reference)
    if r.rc != 0:
        c.check(f"{engine}: disk full at the final write: reference run", False, repr(r))
        return
    h5_size = os.path.getsize(reference)
    name = f"{engine}: disk full at the final write"
    try:
        with tmpfs("3m") as mnt:
            out = os.path.join(mnt, "a.h5")
            r = jdem(earlier, out)
            before = {f: open(os.path.join(mnt, f), "rb").read() for f in ("a.h5", "a.xdmf")}
            r = run_engine(engine, scene, out, before_run=lambda: fill_to(mnt, pages(h5_size)))
            after = {f: open(os.path.join(mnt, f), "rb").read() for f in ("a.h5", "a.xdmf")}
            left = files(mnt)
            part_ok = h5_readable(out + ".part") if "a.h5.part" in left else "absent"
            part_size = os.path.getsize(out + ".part") if "a.h5.part" in left else -1
    except NotRoot as e:
        c.skip(name, str(e))
        return
    c.check(f"{name}: I/O exit code", r.rc == EXIT["io"], repr(r))
    c.check(f"{name}: the reason and where the run is",
            f"cannot write '{out[:-3]}.xdmf.part': No space left on device; the trajectory is "
            f"complete in '{out}.part' (without its sidecar); the previous result is unchanged"
            in r.err, repr(r))
    c.check(f"{name}: the earlier a.h5 and a.xdmf are unchanged", before == after,
            "the earlier result changed")
    c.check(f"{name}: the new run complete and readable in a.h5.part",
            part_ok is None and part_size == h5_size, f".part: {part_ok}, {part_size} bytes "
            f"(the run on a normal disk: {h5_size})")
    c.check(f"{name}: no sidecar .part left", "a.xdmf.part" not in left, str(left))


def case_read_only(c):
    d = scratch()
    scene = write_scene(d, "small", small_scene())
    out_dir = scratch()
    try:
        with read_only(out_dir) as ro:
            r = jdem(scene, os.path.join(ro, "a.h5"))
    except NotRoot as e:
        c.skip("jdem: read-only output directory", str(e))
        return
    c.check("jdem: read-only output directory: I/O exit code and the reason",
            r.rc == EXIT["io"] and "Read-only file system" in r.err, repr(r))
    c.check("jdem: read-only output directory: nothing written", files(out_dir) == [],
            str(files(out_dir)))


def case_memory_limit(c):
    d = scratch()
    scene = write_scene(d, "small", small_scene(steps=20000, every=10))
    for mb in (360, 400):
        r = jdem(scene, os.path.join(d, f"m{mb}.h5"), mem_bytes=mb << 20)
        c.check(f"jdem: ulimit -v {mb} MB: no crash (exit {r.rc})",
                r.rc in (0, EXIT["io"], EXIT["memory"]), repr(r))
        if r.rc == 0:
            c.check(f"jdem: ulimit -v {mb} MB: complete result readable",
                    h5_readable(os.path.join(d, f"m{mb}.h5")) is None, "")


def main():
    c = Checks()
    case_symlinks(c)
    case_concurrent(c)
    case_directory(c)
    case_read_only(c)
    case_disk_full(c, "jdem")
    case_disk_full(c, "liggghts-jdem")
    case_disk_full_at_final_write(c, "jdem")
    case_disk_full_at_final_write(c, "liggghts-jdem")
    case_memory_limit(c)
    return c.exit()


if __name__ == "__main__":
    sys.exit(main())
