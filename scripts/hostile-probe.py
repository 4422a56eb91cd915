#!/usr/bin/env python3
"""Hostile probe of the `moreau` command line (issue 31, "Outputs that cannot hurt").

Runs a `moreau` binary on several hundred hostile cases, each in a fresh temporary directory,
and classifies each run:

  ok           rc 0 and a correct answer (the output is where the target says it goes)
  refused      rc != 0 with a one-line `error: ...` on stderr
  PANIC        stderr contains "panicked", or rc 101
  ABORT        killed by a signal other than SIGPIPE (rc < 0, or 134/136/139 from a wrapper)
  TIMEOUT      still running after the case's limit (10 s); the process group is killed
  REPLACED     a non-regular target or guard (device, FIFO, socket, symlink, directory) is no
               longer what it was (st_mode type, st_rdev, inode, readlink compared before/after)
  OVERWRITTEN  an input file's bytes changed, or the input is gone
  CLOBBERED    a file that belongs to nobody in the command (outside the output, or a foreign
               file put inside an existing output directory) changed or vanished
  LEFTOVER     temp/staging files left behind (new names starting with '.', or containing
               'tmp'/'staging'/'.lock'), or anything created by a refused run
  BIGERR       an error message longer than the case's limit (2000 bytes by default)
  WRONG        expected a written answer and got a refusal, expected a refusal and got rc 0, or
               rc 0 without the output where the target says it goes
  BADERR       rc != 0 without exactly one non-empty stderr line starting with `error`

Every non-clean class makes the exit status 1. `--self-test` runs fake binaries (shell scripts
that replace their target, panic, abort, sleep, overwrite the input, leave temp files...) and
checks that each is classified as it must be: the negative control of this probe.

Only the Python 3.11 standard library is used. Run as root to get the read-only bind mount
cases (a private mount namespace per run, `unshare -m`) and the uid-65534 permission cases;
without root those cases fall back to plain permissions.

  python3 scripts/hostile-probe.py --bin target/release/moreau --json /tmp/probe.json
  python3 scripts/hostile-probe.py --self-test
"""
from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import random
import re
import resource
import select
import shlex
import shutil
import signal
import socket
import stat
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Callable, Optional

REPO = Path(__file__).resolve().parent.parent
SEVERITY = [
    "PANIC", "ABORT", "TIMEOUT", "REPLACED", "OVERWRITTEN", "CLOBBERED", "LEFTOVER", "BIGERR", "WRONG", "BADERR",
]
CLEAN = ["ok", "refused"]
DEFAULT_TIMEOUT = 10.0
NOBODY = 65534
MEM_LIMIT = 4 << 30  # address space of a run: a runaway allocation aborts instead of eating the machine
FSIZE_LIMIT = 1 << 30  # no single file over 1 GiB (disk use of the probe stays bounded)
EXTERNAL = ["/dev/null", "/dev/full", "/dev/zero", "/dev/urandom"]


# --------------------------------------------------------------------------------------------
# Cases


@dataclasses.dataclass
class Case:
    command: str  # e.g. "theta --out"
    target: str  # what is hostile: the target or the input
    argv: list  # arguments after the binary, relative to the work directory
    setup: Callable  # setup(ctx): creates the inputs and the target in ctx.work
    inputs: list = dataclasses.field(default_factory=list)  # files whose bytes must not change
    out: Optional[str] = None  # the output path as given (relative to work)
    out_kind: Optional[str] = None  # "file" or "dir"
    expect: str = "any"  # "ok", "refuse" or "any"
    data_at: str = "path"  # where the written answer lands: path, fifo, stdout, capture, none
    validate: Optional[Callable] = None  # validate(bytes) for files, validate(Path) for dirs
    reader: Optional[str] = None  # FIFO drained by a reader thread during the run
    runner: str = "plain"  # plain, rofs (ro_dir mounted read-only), nobody (uid 65534)
    ro_dir: Optional[str] = None
    stdout: str = "pipe"  # pipe, devfull, closed, or file:<rel> (a regular file in work)
    stdin: str = "null"  # null, or open (a pipe that never ends)
    foreign: list = dataclasses.field(default_factory=list)  # files of nobody: must survive
    guards: list = dataclasses.field(default_factory=list)  # extra paths whose identity must stay
    allow_new: list = dataclasses.field(default_factory=list)
    bigerr_limit: int = 2000
    ok_rcs: tuple = (0,)  # exit codes that are an answer (sweep: 1 when points failed)
    timeout: float = DEFAULT_TIMEOUT
    env: dict = dataclasses.field(default_factory=dict)
    id: str = ""


class Skip(Exception):
    pass


class Ctx:
    def __init__(self, work: Path, cache: Path):
        self.work = work
        self.cache = cache

    def p(self, rel: str) -> Path:
        return self.work / rel

    def put(self, rel: str, data):
        path = self.p(rel)
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(data, str):
            data = data.encode()
        path.write_bytes(data)

    def copy(self, src, rel: str):
        path = self.p(rel)
        path.parent.mkdir(parents=True, exist_ok=True)
        src = Path(src)
        if src.is_dir():
            shutil.copytree(src, path)
        else:
            shutil.copyfile(src, path)

    def link_cache(self, name: str, rel: str):
        """A big cached file, hard-linked (no copy; the bytes are still guarded)."""
        path = self.p(rel)
        path.parent.mkdir(parents=True, exist_ok=True)
        os.link(self.cache / name, path)

    def fifo(self, rel: str):
        os.mkfifo(self.p(rel))

    def symlink(self, target: str, rel: str):
        os.symlink(target, self.p(rel))

    def mkdir(self, rel: str):
        self.p(rel).mkdir(parents=True, exist_ok=True)

    def sparse(self, rel: str, size: int, head: bytes = b""):
        with open(self.p(rel), "wb") as f:
            f.write(head)
            f.truncate(size)

    def socket(self, rel: str):
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            s.bind(str(self.p(rel)))
        except OSError as e:
            raise Skip(f"cannot bind a unix socket: {e}")
        finally:
            s.close()

    def mknod(self, rel: str, kind: str):
        # majors 240-254 are for local/experimental use; 240 has no driver here (checked at start)
        mode = (stat.S_IFCHR if kind == "c" else stat.S_IFBLK) | 0o666
        try:
            os.mknod(self.p(rel), mode, os.makedev(240, 0))
        except OSError as e:
            raise Skip(f"mknod: {e}")


# --------------------------------------------------------------------------------------------
# Base inputs

W_TOML = REPO / "examples/worked-example.toml"
BAM_TOML = REPO / "examples/real/bam-xl330-kp100.toml"
REC_CSV = REPO / "data/bam-servo/xl330-kp100-sin_sin.csv"
TEL_CSV = REPO / "data/robonine-backlash/logs/motor_telemetry_single.csv"
CFG_JSON = REPO / "data/robonine-backlash/analysis_config_m5.json"
SS_JSON = '{"A": [[-1.0]], "B": [[1.0]], "C": [[1.0]], "E": [[0.5]]}\n'
SWEEP_SPEC = (
    'model = "w.toml"\n[[axis]]\nparameter = "input.amplitude"\nvalues = [0.5, 1.0]\n[evaluate]\nmeasure = false\n'
)


def worked() -> str:
    return W_TOML.read_text()


def json_with(key: str):
    def check(data: bytes):
        try:
            v = json.loads(data.decode())
        except Exception as e:  # noqa: BLE001
            return f"not JSON ({str(e)[:80]})"
        if key and key not in json.dumps(v)[:10_000_000]:
            return f"JSON without `{key}`"
        return None

    return check


def text_with(needle: str):
    def check(data: bytes):
        return None if needle.encode() in data else f"no `{needle}` in the output"

    return check


def dir_with(*names: str):
    def check(d: Path):
        if not d.is_dir():
            return f"{d.name} is not a directory"
        have = {e.name for e in d.iterdir()}
        for n in names:
            if n.endswith("*"):
                if not any(h.startswith(n[:-1]) for h in have):
                    return f"no {n} in the output directory"
            elif n not in have:
                return f"no {n} in the output directory"
        return None

    return check


@dataclasses.dataclass
class Writer:
    name: str
    kind: str  # file or dir
    setup: Callable
    inputs: list
    argv: Callable  # argv(target) -> list
    validate: Callable
    first: str = ""  # dir writers: the first file name they write (for member cases)
    full: bool = True  # every target, or the reduced set


def setup_w(ctx):
    ctx.copy(W_TOML, "w.toml")


def setup_ss(ctx):
    ctx.put("ss.json", SS_JSON)


def setup_play(ctx):
    ctx.copy(TEL_CSV, "tel.csv")
    ctx.copy(CFG_JSON, "cfg.json")


def setup_diag(ctx):
    ctx.copy(BAM_TOML, "bam.toml")
    ctx.copy(REC_CSV, "rec.csv")


def setup_sweep(ctx):
    ctx.copy(W_TOML, "w.toml")
    ctx.put("s.toml", SWEEP_SPEC)


def setup_shards(ctx):
    if not (ctx.cache / "shards").is_dir():
        raise Skip("no cached shards (the sweep that makes them failed)")
    ctx.copy(ctx.cache / "shards", "shards")


def setup_sw(ctx):
    if not (ctx.cache / "sw").is_dir():
        raise Skip("no cached sweep (the sweep that makes it failed)")
    ctx.copy(ctx.cache / "sw", "sw")


def setup_none(ctx):
    pass


SHARD_FILES = ["shards/sweep-shard-0-of-2.json", "shards/sweep-shard-1-of-2.json"]

FILE_WRITERS = [
    Writer("theta --out", "file", setup_w, ["w.toml"], lambda t: ["theta", "w.toml", "--out", t], json_with("theta")),
    Writer(
        "import --out", "file", setup_ss, ["ss.json"],
        lambda t: ["import", "ss.json", "--out", t, "--interval", "0.1", "--sine", "1.0"], text_with("[plant]"),
    ),
    Writer(
        "play-width --json", "file", setup_play, ["tel.csv", "cfg.json"],
        lambda t: ["play-width", "--data", "tel.csv", "--config", "cfg.json", "--json", t], json_with(""),
    ),
    Writer(
        "discover-bench --json", "file", setup_none, [],
        lambda t: ["discover-bench", "--classes", "none", "--cases", "1", "--json", t], json_with(""),
    ),
]

DIR_WRITERS = [
    Writer(
        "simulate --out", "dir", setup_w, ["w.toml"], lambda t: ["simulate", "w.toml", "--out", t],
        dir_with("trajectory.csv"), first="trajectory.csv",
    ),
    Writer(
        "diagnose --out", "dir", setup_diag, ["bam.toml", "rec.csv"],
        lambda t: ["diagnose", "--model", "bam.toml", "--data", "rec.csv", "--out", t],
        dir_with("report.json", "report.md"), first="report.json",
    ),
    Writer(
        "sweep --out", "dir", setup_sweep, ["w.toml", "s.toml"], lambda t: ["sweep", "s.toml", "--out", t, "-q"],
        dir_with("sweep.json", "sweep.csv"), first="sweep.json",
    ),
    Writer(
        "merge --out", "dir", setup_shards, SHARD_FILES, lambda t: ["merge", "shards", "--out", t],
        dir_with("sweep.json", "sweep.csv"), first="sweep.json",
    ),
    Writer(
        "figure psi --out", "dir", setup_w, ["w.toml"], lambda t: ["figure", "psi", "w.toml", "--out", t],
        dir_with("fig-psi1.svg", "fig-psi1.png"), first="fig-psi1.svg",
    ),
    Writer(
        "figure sweep --out", "dir", setup_sw, ["sw/sweep.json"],
        lambda t: ["figure", "sweep", "sw", "--out", t, "--format", "svg"], dir_with("sweep-*"), first="sweep-x.svg",
    ),
    Writer(
        "figure trajectory --out", "dir", setup_w, ["w.toml"],
        lambda t: ["figure", "trajectory", "w.toml", "--out", t, "--format", "svg,pdf"],
        dir_with("trajectory-yz.svg"), first="trajectory-yz.svg", full=False,
    ),
    Writer(
        "figure tube --out", "dir", setup_w, ["w.toml"],
        lambda t: ["figure", "tube", "w.toml", "--out", t, "--format", "svg"], dir_with("fig-loop.svg"),
        first="fig-loop.svg", full=False,
    ),
    Writer(
        "check --out", "dir", setup_none, [],
        lambda t: ["check", "--only", "psi0", "--cases", "10", "--negative-control", "--out", t],
        dir_with("psi0-negative-control.toml"), first="psi0-negative-control.toml",
    ),
    Writer(
        "discover-bench --write-cases", "dir", setup_none, [],
        lambda t: ["discover-bench", "--classes", "none", "--cases", "1", "--write-cases", t],
        dir_with("none-0.toml", "none-0.csv"), first="none-0.toml",
    ),
]

LONG_NAME = "n" * 300
LONG_PATH = "/".join(["d" * 200] * 25)  # about 5000 bytes, each component legal


@dataclasses.dataclass
class Target:
    label: str
    out: str
    expect: str
    prep: Callable = lambda ctx: None
    data_at: str = "path"
    reader: Optional[str] = None
    runner: str = "plain"
    ro_dir: Optional[str] = None
    stdout: str = "pipe"
    foreign: list = dataclasses.field(default_factory=list)
    guards: list = dataclasses.field(default_factory=list)
    needs_input: bool = False
    reduced: bool = False  # also in the reduced target set
    bigerr_extra: int = 0


def file_targets(w: Writer) -> list:
    inp = w.inputs[0] if w.inputs else None
    t = [
        Target("new file", "out.json", "ok", reduced=True),
        Target("existing file", "real.json", "ok", lambda c: c.put("real.json", "old")),
        Target("/dev/null", "/dev/null", "ok", data_at="none", reduced=True),
        Target("symlink to /dev/null", "nul", "ok", lambda c: c.symlink("/dev/null", "nul"), data_at="none"),
        Target("/dev/stdout (a pipe)", "/dev/stdout", "ok", data_at="stdout"),
        Target(
            "/dev/stdout (a file)", "/dev/stdout", "ok", lambda c: c.put("captured.out", ""), data_at="capture",
            stdout="file:captured.out", guards=["captured.out"],
        ),
        Target("FIFO with a reader", "out.fifo", "ok", lambda c: c.fifo("out.fifo"), data_at="fifo",
               reader="out.fifo", reduced=True),
        Target("FIFO without a reader", "out.fifo", "any", lambda c: c.fifo("out.fifo"), data_at="none", reduced=True),
        Target("symlink to a file", "link.json",
               "ok", lambda c: (c.put("real.json", "old"), c.symlink("real.json", "link.json"))),
        Target("dangling symlink", "dang.json", "any", lambda c: c.symlink("missing.json", "dang.json")),
        Target(
            "symlink chain", "l1", "ok",
            lambda c: (c.put("real.json", "old"), c.symlink("l2", "l1"), c.symlink("sub/l3", "l2"), c.mkdir("sub"),
                       c.symlink("../real.json", "sub/l3")),
        ),
        Target("symlink loop", "loop1", "refuse", lambda c: (c.symlink("loop2", "loop1"), c.symlink("loop1", "loop2"))),
        Target("symlink to a directory", "dlink", "refuse", lambda c: (c.mkdir("adir"), c.symlink("adir", "dlink"))),
        Target("existing directory", "adir", "refuse", lambda c: c.mkdir("adir")),
        Target("the current directory", ".", "refuse"),
        Target("dir/. (a directory)", "adir/.", "refuse", lambda c: c.mkdir("adir")),
        Target("/dev/full", "/dev/full", "refuse", data_at="none"),
        Target("char device (no driver)", "cdev", "any", lambda c: c.mknod("cdev", "c"), data_at="none"),
        Target("block device (no driver)", "bdev", "refuse", lambda c: c.mknod("bdev", "b"), data_at="none"),
        Target("unix socket", "sock", "refuse", lambda c: c.socket("sock")),
        Target("read-only directory (ro mount)", "ro/out.json", "refuse", lambda c: c.mkdir("ro"), runner="rofs",
               ro_dir="ro"),
        Target("read-only directory (uid 65534, 0555)", "rodir/out.json", "refuse",
               lambda c: (c.mkdir("rodir"), os.chmod(c.p("rodir"), 0o555)), runner="nobody"),
        Target("parent is a regular file", "notes.txt/out.json", "refuse", lambda c: c.put("notes.txt", "mine"),
               foreign=["notes.txt"]),
        Target("missing parent directories", "no/such/dir/out.json", "any"),
        Target("trailing slash (new)", "new.json/", "any"),
        Target("trailing slash (existing file)", "real.json/", "refuse", lambda c: c.put("real.json", "old"),
               foreign=["real.json"]),
        Target("empty path", "", "refuse"),
        Target("name of 300 bytes", LONG_NAME, "refuse", bigerr_extra=2 * len(LONG_NAME)),
        Target("path of 5000 bytes", LONG_PATH + "/out.json", "refuse", bigerr_extra=2 * len(LONG_PATH)),
        Target("newline in the name", "out\nx.json", "ok"),
        Target("/proc (pseudo file system)", "/proc/moreau-probe.json", "refuse", data_at="none"),
    ]
    if inp:
        t += [
            Target("the input itself", inp, "refuse", needs_input=True, reduced=True),
            Target("symlink to the input", "alias", "refuse", lambda c: c.symlink(inp, "alias"), needs_input=True,
                   reduced=True),
            Target("hard link to the input", "hard", "any", lambda c: os.link(c.p(inp), c.p("hard")), needs_input=True),
            Target("./x/../input", f"./x/../{inp}", "refuse", lambda c: c.mkdir("x"), needs_input=True),
            Target("absolute path of the input", "@ABS@" + inp, "refuse", needs_input=True),
        ]
    return t


def dir_targets(w: Writer) -> list:
    inp = w.inputs[0] if w.inputs else None
    first = w.first
    t = [
        Target("new directory", "out", "ok", reduced=True),
        Target("existing empty directory", "out", "ok", lambda c: c.mkdir("out")),
        Target(
            "directory with a foreign file", "out", "any",
            lambda c: (c.mkdir("out"), c.put("out/notes.txt", "mine")), foreign=["out/notes.txt"],
        ),
        Target("/dev/null", "/dev/null", "refuse", data_at="none", reduced=True),
        Target("symlink to /dev/null", "nul", "refuse", lambda c: c.symlink("/dev/null", "nul"), data_at="none"),
        Target("FIFO (no reader)", "out.fifo", "refuse", lambda c: c.fifo("out.fifo"), data_at="none", reduced=True),
        Target("regular file", "real.json", "refuse", lambda c: c.put("real.json", "old"), foreign=["real.json"]),
        Target("symlink to a directory", "dlink", "any", lambda c: (c.mkdir("adir"), c.symlink("adir", "dlink"))),
        Target("dangling symlink", "dang", "any", lambda c: c.symlink("missing", "dang")),
        Target(
            "symlink chain to a directory", "l1", "any",
            lambda c: (c.mkdir("adir"), c.symlink("l2", "l1"), c.symlink("adir", "l2")),
        ),
        Target("symlink loop", "loop1", "refuse", lambda c: (c.symlink("loop2", "loop1"), c.symlink("loop1", "loop2"))),
        Target("the current directory (holds the inputs)", ".", "any", lambda c: c.put("notes.txt", "mine"),
               foreign=["notes.txt"], reduced=True),
        Target("the parent directory", "..", "any", lambda c: c.put("notes.txt", "mine"), foreign=["notes.txt"]),
        Target("read-only directory (ro mount)", "ro/out", "refuse", lambda c: c.mkdir("ro"), runner="rofs",
               ro_dir="ro"),
        Target("existing directory mounted read-only", "ro", "refuse", lambda c: (c.mkdir("ro"), c.put("ro/old", "x")),
               runner="rofs", ro_dir="ro", foreign=["ro/old"]),
        Target("read-only directory (uid 65534, 0555)", "rodir/out", "refuse",
               lambda c: (c.mkdir("rodir"), os.chmod(c.p("rodir"), 0o555)), runner="nobody"),
        Target("parent is a regular file", "notes.txt/out", "refuse", lambda c: c.put("notes.txt", "mine"),
               foreign=["notes.txt"]),
        Target("missing parent directories", "no/such/out", "ok"),
        Target("trailing slash", "out/", "ok"),
        Target("empty path", "", "refuse"),
        Target("name of 300 bytes", LONG_NAME, "refuse", bigerr_extra=2 * len(LONG_NAME)),
        Target("path of 5000 bytes", LONG_PATH + "/out", "refuse", bigerr_extra=2 * len(LONG_PATH)),
        Target("newline in the name", "out\nx", "ok"),
        Target("/dev/full", "/dev/full", "refuse", data_at="none"),
        Target("unix socket", "sock", "refuse", lambda c: c.socket("sock")),
        Target("char device (no driver)", "cdev", "refuse", lambda c: c.mknod("cdev", "c"), data_at="none"),
        Target("/proc (pseudo file system)", "/proc/moreau-probe", "refuse", data_at="none"),
        Target(
            "member is a FIFO (no reader)", "out", "any", lambda c: (c.mkdir("out"), c.fifo("out/" + first)),
        ),
        Target(
            "member is a directory", "out", "any", lambda c: (c.mkdir("out/" + first), c.put(f"out/{first}/keep", "k")),
        ),
    ]
    if inp:
        t += [
            Target("the input itself", inp, "refuse", needs_input=True, reduced=True),
            Target("symlink to the input", "alias", "refuse", lambda c: c.symlink(inp, "alias"), needs_input=True,
                   reduced=True),
            Target(
                "member is a symlink to the input", "out", "any",
                lambda c: (c.mkdir("out"), c.symlink("../" + inp, "out/" + first)), needs_input=True,
            ),
            Target(
                "member is a hard link to the input", "out", "any",
                lambda c: (c.mkdir("out"), os.link(c.p(inp), c.p("out/" + first))), needs_input=True,
            ),
            Target("directory holding the input", "in", "any", needs_input=True),  # inputs moved under in/
        ]
    return t


def writer_cases() -> list:
    cases = []
    for w in FILE_WRITERS + DIR_WRITERS:
        targets = file_targets(w) if w.kind == "file" else dir_targets(w)
        for t in targets:
            if not w.full and not t.reduced:
                continue
            cases.append(target_case(w, t))
    return cases


def target_case(w: Writer, t: Target) -> Case:
    inputs = list(w.inputs)
    argv_inputs = None
    if t.label == "directory holding the input":
        # the inputs live in in/, the command runs on in/<input>, --out in
        inputs = ["in/" + i for i in w.inputs]

        def setup(ctx, w=w, t=t):
            w.setup(ctx)
            ctx.mkdir("in")
            for i in w.inputs:
                src = ctx.p(i)
                dst = ctx.p("in/" + i)
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.rename(src, dst)
            # a sweep spec names its model relative to itself: keep them together
            t.prep(ctx)

        argv_inputs = {i: "in/" + i for i in w.inputs}
    else:

        def setup(ctx, w=w, t=t):
            w.setup(ctx)
            t.prep(ctx)

    out = t.out
    argv = w.argv(out)
    if argv_inputs:
        argv = [argv_inputs.get(a, a) for a in argv]
        # `merge shards` names a directory; `figure sweep sw` too
        for d in ("shards", "sw"):
            if d in argv and any(i.startswith(d + "/") for i in w.inputs):
                argv = ["in/" + d if a == d else a for a in argv]
    return Case(
        command=w.name, target=t.label, argv=argv, setup=setup, inputs=inputs, out=out, out_kind=w.kind,
        expect=t.expect, data_at=t.data_at, validate=w.validate, reader=t.reader, runner=t.runner, ro_dir=t.ro_dir,
        stdout=t.stdout, foreign=list(t.foreign), guards=list(t.guards), bigerr_limit=2000 + t.bigerr_extra,
        ok_rcs=(0, 1) if w.name.startswith("sweep") else (0,),
    )


# --------------------------------------------------------------------------------------------
# Hostile inputs


def model_case(command: str, target: str, text, cmds=("validate", "theta", "simulate"), expect="any", extra=None,
               name="m.toml"):
    """One case per command on the model file `name` holding `text` (bytes, str, or a setup)."""
    out = []
    for cmd in cmds:
        argv, out_path, kind, val = model_argv(cmd, name)

        def setup(ctx, text=text):
            ctx.copy(W_TOML, "w.toml")
            if callable(text):
                text(ctx)
            else:
                ctx.put(name, text)
            if extra:
                extra(ctx)

        out.append(Case(command=cmd, target=target, argv=argv, setup=setup, inputs=["w.toml"] + (
            [name] if not callable(text) else []), out=out_path, out_kind=kind, expect=expect, validate=val))
    return out


def model_argv(cmd: str, name: str):
    if cmd == "validate":
        return ["validate", name], None, None, None
    if cmd == "theta":
        return ["theta", name], None, None, None
    if cmd == "theta --json":
        return ["theta", name, "--json", "--no-measure"], None, None, None
    if cmd == "simulate":
        return ["simulate", name, "--out", "out"], "out", "dir", dir_with("trajectory.csv")
    if cmd == "periodic":
        return ["periodic", name], None, None, None
    if cmd == "convergence":
        return ["convergence", name, "--levels", "3"], None, None, None
    if cmd == "figure psi":
        return ["figure", "psi", name, "--out", "out", "--format", "svg"], "out", "dir", dir_with("fig-psi1.svg")
    if cmd == "diagnose":
        return (["diagnose", "--model", name, "--data", "rec.csv", "--out", "out"], "out", "dir",
                dir_with("report.json"))
    raise ValueError(cmd)


ALL_MODEL_CMDS = ("validate", "theta", "simulate", "periodic", "convergence", "figure psi")


def nested(depth: int, open_: str, close: str, leaf: str = "1") -> str:
    return open_ * depth + leaf + close * depth


def utf16(text: str) -> bytes:
    return b"\xff\xfe" + text.encode("utf-16-le")


def garbage(n: int, seed: int) -> bytes:
    return random.Random(seed).randbytes(n)


def input_cases() -> list:
    W = worked()
    cases = []
    # item 5: huge plant entries below the 1e100 limit
    for v in ["1e60", "1e70", "1e80", "1e90", "1e99"]:
        cases += model_case("model", f"A entry {v}", W.replace("[-2.0, -0.6]", f"[-{v}, -0.6]"),
                            cmds=("theta", "simulate", "periodic"))
    for v in ["1e60", "1e99"]:
        cases += model_case("model", f"E entry {v}", W.replace("E = [[0.0], [1.0]]", f"E = [[0.0], [{v}]]"),
                            cmds=("theta", "simulate"))
        cases += model_case("model", f"B entry {v}", W.replace("B = [[0.0], [1.0]]", f"B = [[0.0], [{v}]]"),
                            cmds=("theta", "simulate"))
        cases += model_case("model", f"C entry {v}", W.replace("C = [[1.0, 0.0]]", f"C = [[{v}, 0.0]]"),
                            cmds=("theta", "simulate"))
        cases += model_case("model", f"A = diag(-{v}, -1) (stiff)",
                            W.replace("A = [[0.0, 1.0], [-2.0, -0.6]]", f"A = [[-{v}, 0.0], [0.0, -1.0]]"),
                            cmds=("theta", "simulate"))
        cases += model_case("model", f"amplitude {v}", W.replace("amplitudes = [1.0]", f"amplitudes = [{v}]"),
                            cmds=("theta", "simulate"))
        cases += model_case("model", f"half_width {v}", W.replace("half_width = 0.1", f"half_width = {v}"),
                            cmds=("theta", "simulate"))
    cases += model_case("model", "omega 1e99", W.replace("omega = 1.0", "omega = 1e99"), cmds=("theta", "simulate"))
    cases += model_case("model", "omega 1e-99", W.replace("omega = 1.0", "omega = 1e-99"), cmds=("theta", "simulate"))
    cases += model_case("model", "half_width 1e-300", W.replace("half_width = 0.1", "half_width = 1e-300"),
                        cmds=("theta", "simulate"))
    cases += model_case("model", "dt 5e-324 (denormal)", W.replace("dt = 1e-3", "dt = 5e-324"),
                        cmds=("theta", "simulate"))
    cases += model_case("model", "periods 2^63-1", W.replace("periods = 20", "periods = 9223372036854775807"),
                        cmds=("validate", "simulate"))
    cases += model_case("model", "periods -1", W.replace("periods = 20", "periods = -1"), cmds=("validate",))
    cases += model_case("model", "periods 2.5", W.replace("periods = 20", "periods = 2.5"), cmds=("validate",))
    # 10 MB strings
    big = "x" * 10_000_000
    cases += model_case("model", "10 MB name", W.replace('name = "worked example (NOTES.md), a = 1"',
                                                         f'name = "{big}"'),
                        cmds=("validate", "theta", "simulate", "figure psi"))
    cases += model_case("model", "10 MB unknown key", W + f"\n{big} = 1\n", cmds=("validate", "theta"))
    cases += model_case("model", "10 MB unknown key value", W + f'\nsurprise = "{big}"\n', cmds=("validate",))
    cases += model_case("model", "10 MB shape name", W.replace('shape = "interval"', f'shape = "{big}"'),
                        cmds=("validate", "theta"))
    cases += model_case("model", "10 MB input kind", W.replace('kind = "sine"', f'kind = "{big}"'),
                        cmds=("validate",))
    cases += model_case("model", "10 MB comment line", W + "#" + big + "\n", cmds=("validate", "theta"))
    cases += model_case("model", "10 MB bare word (syntax error)", W + big + "\n", cmds=("validate",))
    # non-finite and malformed values
    for label, a, b in [
        ("nan in A", "[-2.0, -0.6]", "[nan, -0.6]"),
        ("inf in A", "[-2.0, -0.6]", "[-inf, -0.6]"),
        ("nan amplitude", "amplitudes = [1.0]", "amplitudes = [nan]"),
        ("inf half_width", "half_width = 0.1", "half_width = inf"),
        ("nan dt", "dt = 1e-3", "dt = nan"),
        ("-inf omega", "omega = 1.0", "omega = -inf"),
        ("1e999 in A (overflow literal)", "[-2.0, -0.6]", "[-1e999, -0.6]"),
        ("ragged A", "A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0], [-2.0]]"),
        ("empty A", "A = [[0.0, 1.0], [-2.0, -0.6]]", "A = []"),
        ("string in A", "[-2.0, -0.6]", '["-2.0", -0.6]'),
        ("A not square", "A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0, 0.0], [-2.0, -0.6, 0.0]]"),
        ("duplicate key", "half_width = 0.1", "half_width = 0.1\nhalf_width = 0.2"),
        ("duplicate table", "[theta]", "[plant]\nA = [[1.0]]\n[theta]"),
        ("x0 of wrong length", "x0 = [0.0, 0.0]", "x0 = [0.0, 0.0, 0.0]"),
        ("negative half_width", "half_width = 0.1", "half_width = -0.1"),
    ]:
        cases += model_case("model", label, W.replace(a, b), cmds=("validate", "theta"))
    # deep nesting
    depth = 200_000
    cases += model_case("model", f"array nesting {depth}", W + "\ndeep = " + nested(depth, "[", "]") + "\n",
                        cmds=ALL_MODEL_CMDS)
    cases += model_case("model", f"inline-table nesting {depth}",
                        W + "\ndeep = " + nested(depth, "{a = ", "}") + "\n", cmds=("validate", "theta"))
    cases += model_case("model", "dotted key of 200000 parts", W + "\n" + ".".join(["a"] * depth) + " = 1\n",
                        cmds=("validate",))
    cases += model_case("model", "table header of 200000 parts", W + "\n[" + ".".join(["a"] * depth) + "]\n",
                        cmds=("validate",))
    cases += model_case("model", "array nesting 5000 in A", W.replace("[-2.0, -0.6]", nested(5000, "[", "]")),
                        cmds=("validate",))
    cases += model_case("model", "unclosed array nesting 100000", W + "\nd = " + "[" * 100_000 + "\n",
                        cmds=("validate",))
    # encodings and garbage
    cases += model_case("model", "binary garbage 1 MB", garbage(1 << 20, 31), cmds=("validate", "theta", "simulate"))
    cases += model_case("model", "empty file", b"", cmds=("validate", "theta", "simulate"))
    cases += model_case("model", "whitespace only", b" \n\t\n" * 1000, cmds=("validate",))
    cases += model_case("model", "UTF-16 with BOM", utf16(W), cmds=("validate", "theta"))
    cases += model_case("model", "UTF-8 BOM", b"\xef\xbb\xbf" + W.encode(), cmds=("validate",))
    cases += model_case("model", "NUL bytes inside", W.encode().replace(b"[theta]", b"[theta]\0\0"),
                        cmds=("validate",))
    cases += model_case("model", "invalid UTF-8 in a string", W.encode().replace(b"worked", b"w\xff\xfeorked"),
                        cmds=("validate",))
    cases += model_case("model", "CR line endings only", W.replace("\n", "\r"), cmds=("validate",))
    cases += model_case("model", "n = 1000 plant (5 MB)", big_plant(1000), cmds=("validate", "theta"))
    cases += model_case("model", "sparse 2 GiB file", lambda c: c.sparse("m.toml", 2 << 30, W.encode()),
                        cmds=("validate", "theta"))
    # special files as the model
    for label, make, cmds in [
        ("/dev/zero", lambda c: c.symlink("/dev/zero", "m.toml"), ALL_MODEL_CMDS),
        ("/dev/urandom", lambda c: c.symlink("/dev/urandom", "m.toml"), ("validate", "theta")),
        ("/dev/null", lambda c: c.symlink("/dev/null", "m.toml"), ("validate", "theta")),
        ("FIFO without a writer", lambda c: c.fifo("m.toml"), ALL_MODEL_CMDS),
        ("a directory", lambda c: c.mkdir("m.toml"), ("validate", "theta", "simulate")),
        ("missing file", lambda c: None, ("validate", "theta")),
        ("dangling symlink", lambda c: c.symlink("nowhere.toml", "m.toml"), ("validate",)),
        ("symlink loop", lambda c: (c.symlink("m2.toml", "m.toml"), c.symlink("m.toml", "m2.toml")), ("validate",)),
        ("unix socket", lambda c: c.socket("m.toml"), ("validate",)),
        ("/proc/self/mem", lambda c: c.symlink("/proc/self/mem", "m.toml"), ("validate",)),
        ("/proc/self/status (size 0, has content)", lambda c: c.symlink("/proc/self/status", "m.toml"),
         ("validate",)),
    ]:
        cases += model_case("model", label, make, cmds=cmds)
    for c in model_case("model", "/dev/stdin = a pipe that never ends", lambda c: c.symlink("/dev/stdin", "m.toml"),
                        cmds=("validate", "theta")):
        c.stdin = "open"
        cases.append(c)
    for cmd in ("validate", "theta", "simulate"):
        for c in model_case("model", "permission denied (uid 65534, mode 000)",
                            lambda c: (c.put("m.toml", W), os.chmod(c.p("m.toml"), 0)), cmds=(cmd,)):
            c.runner = "nobody"
            c.inputs.append("m.toml")
            cases.append(c)
    cases += model_case("model", "missing file with a newline in its name", lambda c: None, cmds=("validate",),
                        name="no\nsuch.toml")
    # csv input of a model (item 7 and unbounded reads)
    def csv_model(file: str, period: str = "") -> str:
        return (W.replace('kind = "sine"', f'kind = "csv"\nfile = "{file}"\n{period}')
                .replace("amplitudes = [1.0]\n", "").replace("omega = 1.0\n", ""))
    samples = "t,w\n" + "".join(f"{k * 0.01},{__import__('math').sin(k * 0.01)}\n" for k in range(629))
    for label, setup in [
        ("csv input: /dev/zero", lambda c: (c.put("m.toml", csv_model("/dev/zero")),)),
        ("csv input: FIFO without a writer", lambda c: (c.put("m.toml", csv_model("w.csv")), c.fifo("w.csv"))),
        ("csv input: a directory", lambda c: (c.put("m.toml", csv_model("w.csv")), c.mkdir("w.csv"))),
        ("csv input: the model itself", lambda c: (c.put("m.toml", csv_model("m.toml")),)),
        ("csv input: period 1e12 for 6.28 s of data",
         lambda c: (c.put("m.toml", csv_model("w.csv", "period = 1e12")), c.put("w.csv", samples))),
        ("csv input: header t,wfoo", lambda c: (c.put("m.toml", csv_model("w.csv")),
                                                c.put("w.csv", samples.replace("t,w", "t,wfoo", 1)))),
        ("csv input: 2e6 rows",
         lambda c: (c.put("m.toml", csv_model("w.csv")), c.link_cache("input-2e6.csv", "w.csv"))),
        ("csv input: sparse 2 GiB", lambda c: (c.put("m.toml", csv_model("w.csv")),
                                               c.sparse("w.csv", 2 << 30, samples.encode()))),
        ("csv input: nan sample", lambda c: (c.put("m.toml", csv_model("w.csv")),
                                             c.put("w.csv", samples.replace("\n0.05,", "\n0.05,nan\n0.051,", 1)))),
    ]:
        cases += model_case("model", label, setup, cmds=("validate", "simulate"))
    cases += recording_cases()
    cases += import_cases()
    cases += play_width_cases()
    cases += sweep_cases()
    cases += merge_figure_cases()
    cases += option_cases()
    cases += stdout_cases()
    return cases


def big_plant(n: int) -> str:
    row = lambda i: "[" + ",".join("-1.0" if i == j else "0.0" for j in range(n)) + "]"  # noqa: E731
    col = "[" + ",".join("[1.0]" if i == 0 else "[0.0]" for i in range(n)) + "]"
    c = "[[" + ",".join("1.0" if j == 0 else "0.0" for j in range(n)) + "]]"
    return (f"[plant]\nA = [{','.join(row(i) for i in range(n))}]\nB = {col}\nC = {c}\nE = {col}\n"
            '[theta]\nshape = "interval"\nhalf_width = 0.1\n[input]\nkind = "sine"\namplitudes = [1.0]\nomega = 1.0\n')


def rec_case(target: str, make, expect="any", model=None):
    def setup(ctx):
        ctx.copy(BAM_TOML, "bam.toml")
        if model:
            ctx.put("bam.toml", model)
        make(ctx)

    return Case(command="diagnose (recording)", target=target,
                argv=["diagnose", "--model", "bam.toml", "--data", "rec.csv", "--out", "out"], setup=setup,
                inputs=["bam.toml"], out="out", out_kind="dir", expect=expect, validate=dir_with("report.json"))


def recording_cases() -> list:
    rec = REC_CSV.read_text()
    lines = rec.splitlines()
    head, rows = lines[0], lines[1:]
    body = lambda rs: head + "\n" + "\n".join(rs) + "\n"  # noqa: E731
    swapped = rows[:]
    swapped[10], swapped[11] = swapped[11], swapped[10]
    same_t = [f"0.5,{r.split(',', 1)[1]}" for r in rows]
    dup_t = rows[:20] + [rows[19]] + rows[20:]
    neg = [f"{-float(r.split(',')[0]) - 1},{r.split(',', 1)[1]}" for r in rows]
    neg.reverse()
    tiny = [f"{k * 1e-300},{r.split(',', 1)[1]}" for k, r in enumerate(rows)]
    cell = lambda i, j, v: [",".join(v if (k == i and c == j) else x for c, x in enumerate(r.split(",")))  # noqa: E731
                            for k, r in enumerate(rows)]
    wide = ",".join(["t", "w"] + [f"y{i}" for i in range(100_000)]) + "\n0,0," + ",".join(["0"] * 100_000) + "\n"
    cases = []
    for label, text in [
        ("nan in y", body(cell(50, 2, "nan"))),
        ("inf in w", body(cell(50, 1, "inf"))),
        ("1e300 in y", body(cell(50, 2, "1e300"))),
        ("empty cell", body(cell(50, 2, ""))),
        ("text cell", body(cell(50, 2, "abc"))),
        ("two rows swapped (unsorted t)", body(swapped)),
        ("all timestamps equal", body(same_t)),
        ("duplicate timestamp", body(dup_t)),
        ("negative times", body(neg)),
        ("time steps of 1e-300", body(tiny)),
        ("header only", head + "\n"),
        ("header and one row", body(rows[:1])),
        ("header and two rows", body(rows[:2])),
        ("ragged row", body(rows[:30] + ["0.5,1"] + rows[30:])),
        ("header t,wfoo,y", body(rows).replace("t,w,y", "t,wfoo,y", 1)),
        ("unknown column", body([r + ",1" for r in rows]).replace("t,w,y", "t,w,y,q", 1)),
        ("duplicate column", body([r + ",1" for r in rows]).replace("t,w,y", "t,w,y,y", 1)),
        ("missing y column", "t,w\n" + "\n".join(r.rsplit(",", 1)[0] for r in rows) + "\n"),
        ("CRLF line endings", body(rows).replace("\n", "\r\n")),
        ("quoted fields", body(['"' + r.replace(",", '","') + '"' for r in rows])),
        ("10 MB header name", "t,w," + "y" * 10_000_000 + "\n" + "\n".join(rows) + "\n"),
        ("100000 columns", wide),
        ("10 MB single cell", body(cell(5, 2, "1" * 10_000_000))),
        ("UTF-16 with BOM", utf16(body(rows))),
        ("UTF-8 BOM", b"\xef\xbb\xbf" + body(rows).encode()),
        ("binary garbage 1 MB", garbage(1 << 20, 32)),
        ("empty file", b""),
    ]:
        cases.append(rec_case(label, lambda c, t=text: c.put("rec.csv", t)))
        cases[-1].inputs.append("rec.csv")
    for label, make in [
        ("2e6 rows (60 MB)", lambda c: c.link_cache("rec-2e6.csv", "rec.csv")),
        ("sparse 2 GiB", lambda c: c.sparse("rec.csv", 2 << 30, REC_CSV.read_bytes())),
        ("/dev/zero", lambda c: c.symlink("/dev/zero", "rec.csv")),
        ("/dev/urandom", lambda c: c.symlink("/dev/urandom", "rec.csv")),
        ("FIFO without a writer", lambda c: c.fifo("rec.csv")),
        ("a directory", lambda c: c.mkdir("rec.csv")),
        ("missing", lambda c: None),
    ]:
        cases.append(rec_case(label, make))
        if label.startswith("2e6"):
            cases[-1].inputs.append("rec.csv")
    c = rec_case("permission denied (uid 65534, mode 000)",
                 lambda c: (c.copy(REC_CSV, "rec.csv"), os.chmod(c.p("rec.csv"), 0)))
    c.runner = "nobody"
    cases.append(c)
    c = rec_case("recording is also --out", lambda c: c.copy(REC_CSV, "rec.csv"))
    c.argv = ["diagnose", "--model", "bam.toml", "--data", "rec.csv", "--out", "rec.csv"]
    c.out, c.expect = "rec.csv", "refuse"
    c.inputs.append("rec.csv")
    cases.append(c)
    c = rec_case("model is also --out", lambda c: c.copy(REC_CSV, "rec.csv"))
    c.argv = ["diagnose", "--model", "bam.toml", "--data", "rec.csv", "--out", "bam.toml"]
    c.out, c.expect = "bam.toml", "refuse"
    c.inputs.append("rec.csv")
    cases.append(c)
    B = BAM_TOML.read_text()
    for v in ["1e60", "1e99"]:
        cases.append(rec_case(f"model with an A entry {v}", lambda c: c.copy(REC_CSV, "rec.csv"),
                              model=B.replace("-71.5934", f"-{v}")))
    cases.append(rec_case("model with a 10 MB name", lambda c: c.copy(REC_CSV, "rec.csv"),
                          model=re.sub(r'^name = ".*"$', 'name = "' + "x" * 10_000_000 + '"', B, flags=re.M)))
    for opt in (["--estimation-fraction", "nan"], ["--estimation-fraction", "1.0"], ["--estimation-fraction", "0"],
                ["--estimation-fraction", "-1"], ["--max-effects", "1000000"],
                ["--max-effects", "18446744073709551615"]):
        c = rec_case("option " + " ".join(opt), lambda c: c.copy(REC_CSV, "rec.csv"))
        c.argv = c.argv + opt
        c.command = "diagnose (options)"
        cases.append(c)
    return cases


def mat_v5(arrays, truncate=None) -> bytes:
    """A MATLAB v5 .mat file; arrays: (name, dims, data, class) with optional overrides."""
    hdr = b"MATLAB 5.0 MAT-file, hostile probe".ljust(116, b" ") + b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"

    def el(typ, payload):
        return struct.pack("<II", typ, len(payload)) + payload + b"\0" * ((-len(payload)) % 8)

    body = b""
    for a in arrays:
        name, dims, data = a["name"], a["dims"], a["data"]
        flags = el(6, struct.pack("<II", a.get("cls", 6), 0))
        dimsel = el(5, b"".join(struct.pack("<i", d) for d in dims))
        nameel = el(1, name.encode())
        real = el(9, b"".join(struct.pack("<d", x) for x in data))
        content = flags + dimsel + nameel + real
        nbytes = a.get("nbytes", len(content))
        body += struct.pack("<II", 14, nbytes) + content
    out = hdr + body
    return out[:truncate] if truncate else out


def import_case(target: str, name: str, data, args=("--interval", "0.1", "--sine", "1.0"), expect="any"):
    def setup(ctx):
        if callable(data):
            data(ctx)
        else:
            ctx.put(name, data)

    return Case(command="import (input)", target=target, argv=["import", name, "--out", "out.toml", *args],
                setup=setup, inputs=[] if callable(data) else [name], out="out.toml", out_kind="file",
                expect=expect, validate=text_with("[plant]"))


def import_cases() -> list:
    ok = [{"name": n, "dims": [1, 1], "data": [v]} for n, v in (("A", -1.0), ("B", 1.0), ("C", 1.0), ("E", 0.5))]
    cases = [import_case("valid .mat (positive control)", "ss.mat", mat_v5(ok), expect="ok")]
    bad = lambda **kw: [dict(ok[0], **kw)] + ok[1:]  # noqa: E731
    for label, arrays, trunc in [
        ("dims 3x3 with 1 value", bad(dims=[3, 3]), None),
        ("dims 2^31-1 x 2^31-1", bad(dims=[2**31 - 1, 2**31 - 1]), None),
        ("negative dims", bad(dims=[-1, 5]), None),
        ("zero dims", bad(dims=[0, 0], data=[]), None),
        ("3-d array", bad(dims=[1, 1, 1]), None),
        ("element length 0xfffffff0", bad(nbytes=0xFFFFFFF0), None),
        ("element length 0", bad(nbytes=0), None),
        ("class 99", bad(cls=99), None),
        ("truncated in the middle", ok, 128 + 40),
        ("header only", ok, 128),
        ("header cut short", ok, 60),
        ("A 1x2 with B 1x1", bad(dims=[1, 2], data=[-1.0, 0.0]), None),
    ]:
        cases.append(import_case(f".mat {label}", "ss.mat", mat_v5(arrays, trunc)))
    cases.append(import_case(".mat binary garbage", "ss.mat", garbage(4096, 33)))
    cases.append(import_case(".mat: MATLAB header then garbage", "ss.mat", mat_v5([])[:128] + garbage(4096, 34)))
    depth = 100_000
    n = 1500
    eye = "[" + ",".join("[" + ",".join("-1.0" if i == j else "0" for j in range(n)) + "]" for i in range(n)) + "]"
    col = "[" + ",".join("[1.0]" for _ in range(n)) + "]"
    for label, text in [
        ("JSON nesting 100000", '{"A": ' + nested(depth, "[", "]") + "}"),
        ("JSON object nesting 100000", nested(depth, '{"a": ', "}")),
        ("JSON NaN", SS_JSON.replace("-1.0", "NaN")),
        ("JSON 1e999", SS_JSON.replace("-1.0", "1e999")),
        ("JSON 1e99 entries", SS_JSON.replace("-1.0", "-1e99")),
        ("JSON empty object", "{}"),
        ("JSON A not square", SS_JSON.replace("[[-1.0]]", "[[-1.0, 0.0]]")),
        ("JSON B rows != A rows", SS_JSON.replace('"B": [[1.0]]', '"B": [[1.0], [2.0]]')),
        ("JSON 10 MB key", SS_JSON.replace('"E"', '"' + "k" * 10_000_000 + '": 1, "E"')),
        ("JSON 10 MB string value", SS_JSON.replace('"E": [[0.5]]', '"E": "' + "v" * 10_000_000 + '"')),
        ("JSON duplicate key", SS_JSON.replace('"E"', '"A": [[-2.0]], "E"')),
        ("JSON n = 1500 (20 MB)", f'{{"A": {eye}, "B": {col}, "C": [[{",".join(["1.0"] * n)}]], "E": {col}}}'),
        ("JSON empty file", ""),
        ("JSON UTF-16", utf16(SS_JSON)),
        ("JSON binary garbage", garbage(1 << 16, 35)),
        ("JSON trailing garbage", SS_JSON + "}}}"),
        ("JSON theta and input keys with 10 MB", SS_JSON.replace("}", ', "theta": "' + "t" * 10_000_000 + '"}')),
    ]:
        cases.append(import_case(label, "ss.json", text))
    cases.append(import_case("JSON sparse 2 GiB", "ss.json", lambda c: c.sparse("ss.json", 2 << 30, SS_JSON.encode())))
    cases.append(import_case("/dev/zero as ss.json", "ss.json", lambda c: c.symlink("/dev/zero", "ss.json")))
    cases.append(import_case("FIFO ss.json without a writer", "ss.json", lambda c: c.fifo("ss.json")))
    cases.append(import_case("directory ss.json", "ss.json", lambda c: c.mkdir("ss.json")))
    cases.append(import_case("/dev/zero directly", "/dev/zero", lambda c: None))
    for label, args in [
        ("--interval nan", ("--interval", "nan", "--sine", "1.0")),
        ("--interval -1", ("--interval", "-1", "--sine", "1.0")),
        ("--interval 1e999", ("--interval", "1e999", "--sine", "1.0")),
        ("--ball 0", ("--ball", "0", "--sine", "1.0")),
        ("--sine nan", ("--interval", "0.1", "--sine", "nan")),
        ("--sine 1e99", ("--interval", "0.1", "--sine", "1e99")),
        ("--omega 0", ("--interval", "0.1", "--sine", "1.0", "--omega", "0")),
        ("--omega -inf", ("--interval", "0.1", "--sine", "1.0", "--omega", "-inf")),
        ("--e-from-b 2^64-1", ("--interval", "0.1", "--sine", "1.0", "--e-from-b", "18446744073709551615")),
        ("--name of 100 kB", ("--interval", "0.1", "--sine", "1.0", "--name", "N" * 100_000)),
        ("--name with a newline and quotes", ("--interval", "0.1", "--sine", "1.0", "--name", 'a"\n[plant]\nA = 1')),
        ("--sine with 30000 amplitudes", ("--interval", "0.1", "--sine", ",".join(["1.0"] * 30_000))),
    ]:
        cases.append(import_case("option " + label, "ss.json", SS_JSON, args=args))
    c = import_case("imported model passes validate", "ss.json", SS_JSON, expect="ok")
    cases.append(c)
    return cases


def play_case(target: str, data=None, cfg=None, args=(), expect="any"):
    def setup(ctx):
        if data is None:
            ctx.copy(TEL_CSV, "tel.csv")
        elif callable(data):
            data(ctx)
        else:
            ctx.put("tel.csv", data)
        if cfg is None:
            ctx.copy(CFG_JSON, "cfg.json")
        elif callable(cfg):
            cfg(ctx)
        else:
            ctx.put("cfg.json", cfg)

    inputs = [n for n, v in (("tel.csv", data), ("cfg.json", cfg)) if not callable(v)]
    return Case(command="play-width (input)", target=target,
                argv=["play-width", "--data", "tel.csv", "--config", "cfg.json", "--json", "pw.json", *args],
                setup=setup, inputs=inputs, out="pw.json", out_kind="file", expect=expect, validate=json_with(""))


def play_width_cases() -> list:
    tel = TEL_CSV.read_text().splitlines()
    head, rows = tel[0], tel[1:]
    cfg = CFG_JSON.read_text()
    body = lambda rs: head + "\n" + "\n".join(rs) + "\n"  # noqa: E731
    setcell = lambda r, j, v: ",".join(v if c == j else x for c, x in enumerate(r.split(",")))  # noqa: E731
    cases = [play_case("valid (positive control)", expect="ok")]
    for label, text in [
        ("nan position", body(rows[:40] + [setcell(rows[40], 2, "nan")] + rows[41:])),
        ("1e300 position", body(rows[:40] + [setcell(rows[40], 2, "1e300")] + rows[41:])),
        ("bad timestamp", body(rows[:40] + [setcell(rows[40], 0, "yesterday")] + rows[41:])),
        ("duplicate timestamps", body([rows[0]] * 5 + rows)),
        ("header only", head + "\n"),
        ("empty file", ""),
        ("10 MB header", head + "," + "h" * 10_000_000 + "\n" + "\n".join(rows) + "\n"),
        ("UTF-16 with BOM", utf16(body(rows))),
        ("binary garbage", garbage(1 << 20, 36)),
        ("duplicate column", body([r + "," + r.split(",")[2] for r in rows]).replace(head, head + ",pos (5)", 1)),
    ]:
        cases.append(play_case("data: " + label, data=text))
    cases.append(play_case("data: 5e5 rows (70 MB)", data=lambda c: c.link_cache("tel-5e5.csv", "tel.csv")))
    cases.append(play_case("data: sparse 2 GiB", data=lambda c: c.sparse("tel.csv", 2 << 30, TEL_CSV.read_bytes())))
    cases.append(play_case("data: /dev/zero", data=lambda c: c.symlink("/dev/zero", "tel.csv")))
    cases.append(play_case("data: FIFO without a writer", data=lambda c: c.fifo("tel.csv")))
    cfgv = json.loads(cfg)
    mod = lambda **kw: json.dumps(dict(cfgv, **kw))  # noqa: E731
    for label, text in [
        ("home_tolerance -5", mod(home_tolerance=-5)),
        ("min_segment_samples 0", mod(min_segment_samples=0)),
        ("unknown key", mod(surprise=1)),
        ("10 MB unknown key", mod(**{"k" * 10_000_000: 1})),
        ("10 MB label",
         json.dumps(dict(cfgv, actuated_motors=[dict(cfgv["actuated_motors"][0], label="L" * 10_000_000)]))),
        ("JSON nesting 100000", nested(100_000, '{"a": ', "}")),
        ("array nesting 100000", '{"home_motor_ids": ' + nested(100_000, "[", "]") + "}"),
        ("1e999 home_position", cfg.replace('"home_position": 2047', '"home_position": 1e999')),
        ("motor id 2^64", cfg.replace('"motor_id": 3', '"motor_id": 18446744073709551616')),
        ("1e6 actuated motors", mod(actuated_motors=[cfgv["actuated_motors"][0]] * 1_000_000)),
        ("empty object", "{}"),
        ("empty file", ""),
        ("binary garbage", garbage(4096, 37)),
    ]:
        cases.append(play_case("config: " + label, cfg=text))
    cases.append(play_case("config: /dev/zero", cfg=lambda c: c.symlink("/dev/zero", "cfg.json")))
    cases.append(play_case("config: FIFO without a writer", cfg=lambda c: c.fifo("cfg.json")))
    for label, args in [("--min-segment-samples 2^64-1", ("--min-segment-samples", "18446744073709551615")),
                        ("--skip-samples 2^64-1", ("--skip-samples", "18446744073709551615")),
                        ("--min-segment-samples 0", ("--min-segment-samples", "0"))]:
        cases.append(play_case("option " + label, args=args))
    c = play_case("data is also --json")
    c.argv = ["play-width", "--data", "tel.csv", "--config", "cfg.json", "--json", "tel.csv"]
    c.out, c.expect = "tel.csv", "refuse"
    cases.append(c)
    c = play_case("config is also --json (via symlink)")
    c.argv = ["play-width", "--data", "tel.csv", "--config", "cfg.json", "--json", "cfg-alias.json"]
    orig = c.setup
    c.setup = lambda ctx, orig=orig: (orig(ctx), ctx.symlink("cfg.json", "cfg-alias.json"))
    c.out, c.expect = "cfg-alias.json", "refuse"
    cases.append(c)
    return cases


def sweep_case(target: str, spec, args=(), expect="any", extra=None):
    def setup(ctx):
        ctx.copy(W_TOML, "w.toml")
        if callable(spec):
            spec(ctx)
        else:
            ctx.put("s.toml", spec)
        if extra:
            extra(ctx)

    return Case(command="sweep (input)", target=target, argv=["sweep", "s.toml", "--out", "out", "-q", *args],
                setup=setup, inputs=["w.toml"] + ([] if callable(spec) else ["s.toml"]), out="out", out_kind="dir",
                expect=expect, validate=dir_with("sweep.json"), ok_rcs=(0, 1))


def sweep_cases() -> list:
    S = SWEEP_SPEC
    cases = [sweep_case("valid (positive control)", S, expect="ok")]
    for label, text in [
        ("model = /dev/zero", S.replace('"w.toml"', '"/dev/zero"')),
        ("model = the spec itself", S.replace('"w.toml"', '"s.toml"')),
        ("model = a directory", S.replace('"w.toml"', '"."')),
        ("model = missing", S.replace('"w.toml"', '"nowhere.toml"')),
        ("model path of 5000 bytes", S.replace('"w.toml"', '"' + LONG_PATH + '"')),
        ("10 MB parameter name", S.replace("input.amplitude", "p" * 10_000_000)),
        ("unknown parameter", S.replace("input.amplitude", "plant.A[99][99]")),
        ("values = []", S.replace("[0.5, 1.0]", "[]")),
        ("values = [nan]", S.replace("[0.5, 1.0]", "[nan]")),
        ("values = [1e99]", S.replace("[0.5, 1.0]", "[1e99]")),
        ("values = [inf]", S.replace("[0.5, 1.0]", "[inf]")),
        ("range from inf", S.replace("values = [0.5, 1.0]", "range = { from = 1.0, to = inf, count = 3 }")),
        ("range count 0", S.replace("values = [0.5, 1.0]", "range = { from = 1.0, to = 2.0, count = 0 }")),
        ("range count 3.5", S.replace("values = [0.5, 1.0]", "range = { from = 1.0, to = 2.0, count = 3.5 }")),
        ("range count -1", S.replace("values = [0.5, 1.0]", "range = { from = 1.0, to = 2.0, count = -1 }")),
        ("2000000 values (over the point budget)",
         S.replace("[0.5, 1.0]", "[" + ",".join(["1.0"] * 2_000_000) + "]")),
        ("two axes on one parameter", S + '[[axis]]\nparameter = "input.amplitude"\nvalues = [2.0]\n'),
        ("six axes of 100 values (1e12 points)",
         S + "".join(f'[[axis]]\nparameter = "input.amplitude"\nvalues = [{",".join(["1.0"] * 100)}]\n'
                     for _ in range(6))),
        ("array nesting 200000", S + "deep = " + nested(200_000, "[", "]") + "\n"),
        ("binary garbage", garbage(1 << 16, 38)),
        ("empty file", ""),
        ("UTF-16", utf16(S)),
        ("evaluate.pairs = 2^63-1", S + "pairs = 9223372036854775807\n"),
        ("digits = 1000000", S + "[table]\ndigits = 1000000\n"),
        ("10 MB caption", S + '[table]\ncaption = "' + "c" * 10_000_000 + '"\n'),
    ]:
        cases.append(sweep_case(label, text))
        if label.startswith("model path of"):  # a path read from the spec may come back twice
            cases[-1].bigerr_limit = 2000 + 2 * len(LONG_PATH)
    cases.append(sweep_case("model = FIFO without a writer", S.replace('"w.toml"', '"m.fifo"'),
                            extra=lambda c: c.fifo("m.fifo")))
    cases.append(sweep_case("spec = /dev/zero", lambda c: c.symlink("/dev/zero", "s.toml")))
    cases.append(sweep_case("spec = FIFO without a writer", lambda c: c.fifo("s.toml")))
    for label, args in [
        ("--shard 5/2", ("--shard", "5/2")), ("--shard 0/0", ("--shard", "0/0")),
        ("--shard 2^64", ("--shard", "0/18446744073709551616")), ("--shard -1/2", ("--shard=-1/2",)),
        ("--shard 1/2/3", ("--shard", "1/2/3")), ("--threads 0", ("--threads", "0")),
        ("--digits 1000000", ("--digits", "1000000")), ("--digits 0", ("--digits", "0")),
        ("--overwrite --fresh --retry-failed", ("--overwrite", "--fresh", "--retry-failed")),
    ]:
        cases.append(sweep_case("option " + label, S, args=args))
    cases.append(sweep_case("--out is the spec", S, expect="refuse"))
    cases[-1].argv = ["sweep", "s.toml", "--out", "s.toml", "-q"]
    cases[-1].out = "s.toml"
    cases.append(sweep_case("--out is the model", S, expect="refuse"))
    cases[-1].argv = ["sweep", "s.toml", "--out", "w.toml", "-q"]
    cases[-1].out = "w.toml"
    return cases


def merge_figure_cases() -> list:
    cases = []

    def merge(target, make, argv_in=("shards",), args=(), expect="any", inputs=()):
        def setup(ctx):
            setup_shards(ctx)
            make(ctx)

        cases.append(Case(command="merge (input)", target=target, argv=["merge", *argv_in, "--out", "merged", *args],
                          setup=setup, inputs=list(inputs), out="merged", out_kind="dir", expect=expect,
                          validate=dir_with("sweep.json")))

    shard0 = "shards/sweep-shard-0-of-2.json"
    merge("valid (positive control)", lambda c: None, expect="ok", inputs=SHARD_FILES)
    merge("one shard missing (no --partial)", lambda c: os.remove(c.p(shard0)), expect="refuse")
    merge("one shard missing, --partial", lambda c: os.remove(c.p(shard0)), args=("--partial",), expect="ok")
    merge("empty directory", lambda c: c.mkdir("empty"), argv_in=("empty",), expect="refuse")
    merge("missing input", lambda c: None, argv_in=("nowhere",), expect="refuse")
    merge("garbage shard", lambda c: c.put(shard0, garbage(4096, 39)), expect="refuse")
    merge("empty shard", lambda c: c.put(shard0, ""), expect="refuse")
    merge("JSON nesting 100000 shard", lambda c: c.put(shard0, nested(100_000, "[", "]")), expect="refuse")
    merge("shard = /dev/zero", lambda c: (os.remove(c.p(shard0)), c.symlink("/dev/zero", shard0)), expect="refuse")
    merge("shard = FIFO without a writer", lambda c: (os.remove(c.p(shard0)), c.fifo(shard0)), expect="refuse")
    merge("shard sparse 2 GiB", lambda c: c.sparse(shard0, 2 << 30, b"{"), expect="refuse")
    merge("the same shard twice", lambda c: None, argv_in=(shard0, shard0, "shards/sweep-shard-1-of-2.json"))
    merge("conflicting extra JSON in the folder", lambda c: c.put("shards/extra.json", '{"points": [1, 2, 3]}'))
    merge("--digits 1000000", lambda c: None, args=("--digits", "1000000"))
    for label, out in [("--out is the shard folder", "shards"), ("--out is a shard file", shard0)]:
        cases.append(Case(command="merge (input)", target=label, argv=["merge", "shards", "--out", out],
                          setup=setup_shards, inputs=SHARD_FILES, out=out, out_kind="dir", expect="any",
                          validate=dir_with("sweep.json")))
    # figure sweep inputs
    def fig(target, make, args=(), expect="any", kind="sweep", inp="sw"):
        def setup(ctx):
            setup_sw(ctx)
            ctx.copy(W_TOML, "w.toml")
            make(ctx)

        cases.append(Case(command=f"figure {kind} (input)", target=target,
                          argv=["figure", kind, inp, "--out", "figs", *args], setup=setup, inputs=["w.toml"],
                          out="figs", out_kind="dir", expect=expect))

    fig("sweep.json garbage", lambda c: c.put("sw/sweep.json", garbage(4096, 40)), expect="refuse")
    fig("sweep.json empty", lambda c: c.put("sw/sweep.json", ""), expect="refuse")
    fig("sweep.json nesting 100000", lambda c: c.put("sw/sweep.json", nested(100_000, "[", "]")), expect="refuse")
    fig("sweep.json = /dev/zero", lambda c: (os.remove(c.p("sw/sweep.json")), c.symlink("/dev/zero", "sw/sweep.json")),
        expect="refuse")
    fig("sweep.json = FIFO", lambda c: (os.remove(c.p("sw/sweep.json")), c.fifo("sw/sweep.json")), expect="refuse")
    fig("directory without sweep.json", lambda c: c.mkdir("nothing"), inp="nothing", expect="refuse")
    fig("--columns unknown", lambda c: None, args=("--columns", "nope"), expect="refuse")
    fig("--columns with 20000 names", lambda c: None, args=("--columns", ",".join(["theta"] * 20_000)))
    fig("--x unknown", lambda c: None, args=("--x", "nope"), expect="refuse")
    for label, args in [
        ("--width 100000 --height 100000", ("--width", "100000", "--height", "100000")),
        ("--width 0", ("--width", "0")),
        ("--width 4294967295", ("--width", "4294967295")),
        ("--dpi 1e9", ("--dpi", "1e9")),
        ("--dpi nan", ("--dpi", "nan")),
        ("--dpi -1", ("--dpi", "-1")),
        ("--dpi 1e-9", ("--dpi", "1e-9")),
    ]:
        fig(label, lambda c: None, args=args + ("--format", "png"), kind="psi", inp="w.toml")
    for label, args in [
        ("--t-end nan", ("--t-end", "nan")), ("--t-end -1", ("--t-end", "-1")), ("--t-end inf", ("--t-end", "inf")),
        ("--dt 1e-9", ("--dt", "1e-9")), ("--dt nan", ("--dt", "nan")),
        ("--width 100000 --height 100000 pdf", ("--width", "100000", "--height", "100000", "--format", "pdf")),
    ]:
        fig(label, lambda c: None, args=args, kind="trajectory", inp="w.toml")
    return cases


def option_cases() -> list:
    cases = []

    def opt(command, argv, expect="any", out=None, kind=None):
        cases.append(Case(command=command, target="option " + " ".join(a[:40] for a in argv[2:]), argv=argv,
                          setup=setup_w, inputs=["w.toml"] if "w.toml" in argv else [], out=out, out_kind=kind,
                          expect=expect))

    for a in (["--max-rows", "0"], ["--max-rows", "18446744073709551615"], ["--periods", "0"], ["--dt", "nan"],
              ["--dt", "-1e-3"], ["--integrator", "event", "--dt", "1e-7"]):
        opt("simulate (options)", ["simulate", "w.toml", "--out", "out", *a], out="out", kind="dir")
    for a in (["--h0", "nan"], ["--h0", "-1"], ["--h0", "1e99"], ["--h0", "0"], ["--levels", "0"], ["--levels", "1"],
              ["--periods", "0"], ["--h0", "1e-12", "--levels", "2"]):
        opt("convergence (options)", ["convergence", "w.toml", *a])
    for a in (["--dt", "nan"], ["--dt", "-1"], ["--dt", "inf"], ["--periods", "0"], ["--pairs", "1000000"],
              ["--pairs", "18446744073709551615"], ["--periods", "11"]):
        opt("periodic (options)", ["periodic", "w.toml", *a])
    for a in (["--cases", "0"], ["--only", "bogus"], ["--only", "x" * 100_000], ["--seed", "18446744073709551615",
                                                                                  "--only", "psi0", "--cases", "5"],
              ["--cases", "18446744073709551615", "--only", "psi0"]):
        opt("check (options)", ["check", *a])
    for a in (["--cases", "0"], ["--classes", "bogus"], ["--classes", ",".join(["none"] * 10_000), "--cases", "1"],
              ["--seed", "18446744073709551615", "--classes", "none", "--cases", "1"]):
        opt("discover-bench (options)", ["discover-bench", *a])
    c = Case(command="discover-bench (options)", target="--json and --write-cases are one path",
             argv=["discover-bench", "--classes", "none", "--cases", "1", "--json", "same", "--write-cases", "same"],
             setup=setup_none, out="same", out_kind="dir", expect="any")
    cases.append(c)
    c = Case(command="discover-bench (options)", target="--json <unwritable> (fails before the work?)",
             argv=["discover-bench", "--cases", "1", "--json", "notes.txt/x.json"],
             setup=lambda ctx: ctx.put("notes.txt", "mine"), foreign=["notes.txt"], expect="refuse", timeout=10.0)
    cases.append(c)
    for argv in (["theta", "w.toml", "--no-measure", "--no-stationary", "--explain"], ["theta", "w.toml", "--explain"]):
        opt("theta (options)", argv, expect="ok")
    # valid examples: positive controls
    for ex in sorted((REPO / "examples").glob("*.toml")):
        def setup(ctx, ex=ex):
            ctx.copy(ex, ex.name)

        cases.append(Case(command="theta (examples)", target=ex.name, argv=["theta", ex.name, "--no-guidance"],
                          setup=setup, inputs=[ex.name], expect="ok"))
    return cases


def stdout_cases() -> list:
    """Standard output that is /dev/full, or a pipe whose reader is gone."""
    cases = []
    commands = [
        ["validate", "w.toml"], ["theta", "w.toml", "--no-measure"], ["theta", "w.toml", "--json", "--no-measure"],
        ["periodic", "w.toml"], ["convergence", "w.toml", "--levels", "2"], ["check", "--only", "psi0", "--cases", "5"],
        ["check", "--only", "psi0", "--cases", "5", "--json"], ["simulate", "w.toml", "--out", "out"],
        ["import", "ss.json", "--out", "out.toml", "--interval", "0.1", "--sine", "1.0"],
        ["play-width", "--data", "tel.csv", "--config", "cfg.json"],
        ["discover-bench", "--classes", "none", "--cases", "1"], ["figure", "psi", "w.toml", "--out", "out"],
        ["sweep", "s.toml", "--out", "out"], ["--help"], ["theta", "--help"], ["--version"],
    ]

    def setup(ctx):
        setup_sweep(ctx)
        setup_ss(ctx)
        setup_play(ctx)

    for argv in commands:
        for mode in ("devfull", "closed"):
            out = "out" if "out" in argv else ("out.toml" if "out.toml" in argv else None)
            cases.append(Case(command=(argv[0] + " (stdout)"), target=f"stdout = {mode}", argv=argv, setup=setup,
                              inputs=["w.toml", "s.toml", "ss.json", "tel.csv", "cfg.json"], out=out,
                              out_kind="file" if out == "out.toml" else ("dir" if out else None), expect="any",
                              stdout=mode, allow_new=[out] if out else []))
    return cases


# --------------------------------------------------------------------------------------------
# Running and classifying


def file_hash(path: str, st) -> str:
    if st.st_size > (64 << 20):  # sparse or big: size, mtime and both ends
        h = hashlib.sha256(f"{st.st_size}:{st.st_mtime_ns}".encode())
        with open(path, "rb") as f:
            h.update(f.read(1 << 20))
            f.seek(max(0, st.st_size - (1 << 20)))
            h.update(f.read(1 << 20))
        return h.hexdigest()
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(1 << 22):
            h.update(chunk)
    return h.hexdigest()


def entry(path: str) -> Optional[dict]:
    try:
        st = os.lstat(path)
    except OSError:
        return None
    e = {"fmt": stat.S_IFMT(st.st_mode), "rdev": st.st_rdev, "ino": st.st_ino, "dev": st.st_dev}
    if stat.S_ISLNK(st.st_mode):
        e["link"] = os.readlink(path)
    elif stat.S_ISREG(st.st_mode):
        try:
            e["hash"] = file_hash(path, st)
        except OSError as err:
            e["hash"] = f"unreadable: {err}"
    return e


def snapshot(root: str) -> dict:
    out = {}

    def walk(p):
        e = entry(p)
        if e is None:
            return
        out[p] = e
        if e["fmt"] == stat.S_IFDIR:
            try:
                names = sorted(os.listdir(p))
            except OSError:
                return
            for n in names:
                walk(os.path.join(p, n))

    walk(root)
    return out


def kind_name(fmt: int) -> str:
    return {stat.S_IFREG: "file", stat.S_IFDIR: "directory", stat.S_IFLNK: "symlink", stat.S_IFIFO: "FIFO",
            stat.S_IFCHR: "char device", stat.S_IFBLK: "block device", stat.S_IFSOCK: "socket"}.get(fmt, "?")


def within(p: str, root: Optional[str]) -> bool:
    return root is not None and (p == root or p.startswith(root.rstrip("/") + "/"))


class FifoReader(threading.Thread):
    """Holds a FIFO open for reading (non-blocking) and drains it until the run ends."""

    def __init__(self, path: str):
        super().__init__(daemon=True)
        self.fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        self.data = bytearray()
        self.done = threading.Event()

    def run(self):
        try:
            while True:
                r, _, _ = select.select([self.fd], [], [], 0.05)
                chunk = b""
                if r:
                    try:
                        chunk = os.read(self.fd, 1 << 16)
                    except BlockingIOError:
                        chunk = None
                if chunk:
                    self.data += chunk
                    continue
                if self.done.is_set():
                    try:  # last drain
                        while more := os.read(self.fd, 1 << 16):
                            self.data += more
                    except OSError:
                        pass
                    return
                time.sleep(0.02)
        finally:
            os.close(self.fd)


def preexec():
    resource.setrlimit(resource.RLIMIT_AS, (MEM_LIMIT, MEM_LIMIT))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_FSIZE, (FSIZE_LIMIT, FSIZE_LIMIT))
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)


class Prober:
    def __init__(self, binary: str, base: Path, cache: Path, keep: bool, timeout_scale: float = 1.0):
        self.binary = binary
        self.base = base
        self.cache = cache
        self.keep = keep
        self.timeout_scale = timeout_scale
        self.can_rofs = root_can_rofs(base)
        self.can_nobody = os.geteuid() == 0
        self.nobody_bin = None
        if self.can_nobody:
            nb = base / "bin"
            nb.mkdir(exist_ok=True)
            self.nobody_bin = str(nb / "moreau")
            shutil.copy2(binary, self.nobody_bin)
            os.chmod(self.nobody_bin, 0o755)

    def run(self, case: Case) -> dict:
        cdir = self.base / case.id
        work = cdir / "work"
        work.mkdir(parents=True)
        ctx = Ctx(work, self.cache)
        res = {"id": case.id, "command": case.command, "target": case.target, "expect": case.expect,
               "argv": [a if len(a) <= 300 else a[:300] + f"...({len(a)} bytes)" for a in case.argv]}
        try:
            case.setup(ctx)
        except Skip as e:
            res.update(cls="skipped", classes=["skipped"], detail=str(e), rc=None, time=0.0, stderr_first="")
            self.cleanup(cdir)
            return res
        argv_rel = [str(work / a[5:]) if a.startswith("@ABS@") else a for a in case.argv]
        out = case.out
        if out is not None and out.startswith("@ABS@"):
            out = str(work / out[5:])
        binary = self.binary
        runner = case.runner
        user = None
        wrap = []
        if runner == "nobody":
            if not self.can_nobody:
                runner = "plain"
            else:
                binary = self.nobody_bin
                user = NOBODY
                os.chmod(self.base, 0o755)
                os.chmod(cdir, 0o755)
        if runner == "rofs":
            if self.can_rofs:
                wrap = ["unshare", "-m", "--propagation", "private", "sh", "-c",
                        'mount --bind "$1" "$1" && mount -o remount,bind,ro "$1" && shift && exec "$@"', "sh",
                        str(work / case.ro_dir)]
            else:  # fall back to a 0555 directory (meaningless as root; the case then says so)
                os.chmod(work / case.ro_dir, 0o555)
                res["note"] = "no read-only mount: 0555 directory"
        argv = wrap + [binary] + argv_rel
        # resolved output (before the run: the links it follows)
        resolved = None
        if out and case.data_at == "capture":
            resolved = str(work / case.stdout[5:])
        elif out and not (os.path.isabs(out) and not out.startswith(str(work))):  # not /dev/..., /proc/...
            try:
                resolved = os.path.realpath(os.path.join(work, out))
            except (OSError, ValueError):
                resolved = None
        inputs = {str(work / i) for i in case.inputs}
        foreign = {str(work / f) for f in case.foreign}
        before = snapshot(str(cdir))
        ext_before = {p: entry(p) for p in EXTERNAL}
        guard_before = {str(work / g): entry(str(work / g)) for g in case.guards}
        # stdio
        stdin = subprocess.DEVNULL
        stdin_w = None
        if case.stdin == "open":
            rfd, stdin_w = os.pipe()
            stdin = rfd
        stdout_spec = subprocess.PIPE
        closers = []
        if case.stdout == "devfull":
            stdout_spec = open("/dev/full", "wb")
            closers.append(stdout_spec)
        elif case.stdout == "closed":
            r, wfd = os.pipe()
            os.close(r)
            stdout_spec = wfd
            closers.append(wfd)
        elif case.stdout.startswith("file:"):
            stdout_spec = open(work / case.stdout[5:], "ab")
            closers.append(stdout_spec)
        reader = FifoReader(str(work / case.reader)) if case.reader else None
        if reader:
            reader.start()
        env = dict(os.environ)
        env.pop("RUST_BACKTRACE", None)
        env.update(case.env)
        timeout = case.timeout * self.timeout_scale
        t0 = time.monotonic()
        timed_out = False
        try:
            p = subprocess.Popen(argv, cwd=work, stdin=stdin, stdout=stdout_spec, stderr=subprocess.PIPE, env=env,
                                 start_new_session=True, preexec_fn=preexec, user=user,
                                 group=NOBODY if user else None, extra_groups=[] if user else None)
        except OSError as e:
            res.update(cls="skipped", classes=["skipped"], detail=f"cannot start: {e}", rc=None, time=0.0,
                       stderr_first="")
            self.cleanup(cdir)
            return res
        for c in closers:
            if isinstance(c, int):
                os.close(c)
            else:
                c.close()
        if stdin_w is not None:
            os.close(stdin)
        try:
            so, se = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            killpg(p.pid)
            so, se = p.communicate()
        elapsed = time.monotonic() - t0
        killpg(p.pid)  # anything it left running in its group
        if stdin_w is not None:
            os.close(stdin_w)
        if reader:
            reader.done.set()
            reader.join(5)
        so = so or b""
        se = se or b""
        rc = p.returncode
        after = snapshot(str(cdir))
        ext_after = {p_: entry(p_) for p_ in EXTERNAL}
        classes, details, notes = self.classify(case, work, cdir, rc, timed_out, so, se, before, after, ext_before,
                                         ext_after, guard_before, inputs, foreign, resolved, reader)
        lines = [ln for ln in se.decode(errors="replace").splitlines() if ln.strip()]
        res.update(rc=rc, time=round(elapsed, 3), classes=classes, cls=classes[0], detail="; ".join(details),
                   notes=notes,
                   stderr_first=(lines[0][:300] if lines else ""), stderr_bytes=len(se), stderr_lines=len(lines),
                   stderr_key=key_line(lines)[:300],
                   stdout_bytes=len(so))
        if res["cls"] not in CLEAN and self.keep:
            res["kept"] = str(cdir)
        else:
            self.cleanup(cdir)
        return res

    def classify(self, case, work, cdir, rc, timed_out, so, se, before, after, ext_before, ext_after, guard_before,
                 inputs, foreign, resolved, reader):
        cls, det, notes = [], [], []
        text = se.decode(errors="replace")
        if "panicked" in text or rc == 101:
            cls.append("PANIC")
            det.append("panic")
        sig = -rc if rc is not None and rc < 0 else None
        if not timed_out and ((sig and sig != signal.SIGPIPE) or rc in (134, 136, 137, 139)):
            cls.append("ABORT")
            det.append(f"signal {signal_name(sig)}" if sig else f"rc {rc}")
        if timed_out:
            cls.append("TIMEOUT")
            det.append(f"over {case.timeout * self.timeout_scale:.0f} s")
        # identity of non-regular things and of every file that is not ours
        exempt = resolved if rc == 0 else None  # a refused run must leave even its target alone
        replaced, overwritten, clobbered = [], [], []
        for p, e in before.items():
            a = after.get(p)
            rel = os.path.relpath(p, work)
            if p in inputs:
                if a is None:
                    overwritten.append(f"input {rel} is gone")
                elif a.get("hash") != e.get("hash") or a["fmt"] != e["fmt"]:
                    overwritten.append(f"input {rel} changed")
                continue
            if p in foreign:
                if a is None or a.get("hash") != e.get("hash") or a["fmt"] != e["fmt"]:
                    clobbered.append(f"{rel} ({'gone' if a is None else 'changed'})")
                continue
            inside = within(p, exempt)
            is_root = exempt is not None and p == exempt
            if e["fmt"] != stat.S_IFREG:
                guarded = not inside or (is_root and (case.out_kind == "file" or e["fmt"] != stat.S_IFDIR))
                if p == str(cdir) or p == str(work):
                    guarded = True
                if guarded:
                    what = replaced_what(e, a)
                    if what:
                        replaced.append(f"{rel}: {what}")
            elif not inside:
                if a is None or a.get("hash") != e.get("hash") or a["fmt"] != e["fmt"]:
                    clobbered.append(f"{rel} ({'gone' if a is None else 'changed to ' + kind_name(a['fmt'])})")
        for p, e in list(ext_before.items()) + list(guard_before.items()):
            a = entry(p) if p in guard_before else ext_after.get(p)
            if e is None:
                continue
            what = replaced_what(e, a)
            if what:
                replaced.append(f"{p}: {what}")
        if replaced:
            cls.append("REPLACED")
            det.append("replaced " + ", ".join(replaced[:3]))
        if overwritten:
            cls.append("OVERWRITTEN")
            det.append(", ".join(overwritten[:3]))
        if clobbered:
            cls.append("CLOBBERED")
            det.append("clobbered " + ", ".join(clobbered[:3]))
        # new entries
        leftovers = []
        ancestors = set()
        if resolved:
            q = resolved
            while q and q != "/":
                ancestors.add(q)
                q = os.path.dirname(q)
        allow = {str(work / a) for a in case.allow_new}
        for p in after:
            if p in before:
                continue
            name = os.path.basename(p)
            rel = os.path.relpath(p, work)
            # `.moreau-outputs` is the manifest of a folder output (the files the run wrote)
            hidden = (name.startswith(".") and name != ".moreau-outputs") or "tmp" in name.lower() \
                or "staging" in name or name.endswith(".lock")
            if hidden:
                leftovers.append(rel)
            elif rc != 0 and not any(within(p, a) for a in allow):
                leftovers.append(rel + " (after a failure)")
            elif rc == 0 and not within(p, resolved) and p not in ancestors and not any(within(p, a) for a in allow):
                leftovers.append(rel + " (stray)")
        if rc in case.ok_rcs:  # an answer with a non-zero code (sweep: failed points) may write
            leftovers = [x for x in leftovers if not x.endswith("(after a failure)")]
        if leftovers and not timed_out:
            cls.append("LEFTOVER")
            det.append("left " + ", ".join(sorted(leftovers)[:3]))
        # what the user typed may come back: a long argument raises the limit by twice its length
        limit = case.bigerr_limit + 2 * sum(len(a) for a in case.argv if len(a) > 1000)
        if rc not in (0, None) and len(se) > limit and not timed_out:
            cls.append("BIGERR")
            det.append(f"stderr {len(se)} bytes")
        crashed = bool(set(cls) & {"PANIC", "ABORT", "TIMEOUT"})
        if not crashed:
            quiet_pipe = case.stdout == "closed" and rc in (141, -signal.SIGPIPE)
            if rc in case.ok_rcs and rc != 0:
                last = text.strip().splitlines()[-1][:120] if text.strip() else ""
                notes.append(f"rc {rc} counted as an answer: {last}")
            if rc == 0 or rc in case.ok_rcs:
                if case.expect == "refuse":
                    cls.append("WRONG")
                    det.append("accepted (rc 0) where a refusal was expected")
                else:
                    problem = self.check_output(case, work, resolved, so, reader)
                    if problem:
                        cls.append("WRONG")
                        det.append(problem)
            elif not quiet_pipe:
                if case.expect == "ok":
                    cls.append("WRONG")
                    det.append("refused a legitimate target")
                # one error line, the last one; progress or information lines before it are allowed
                # (noted: a refused output target after the work)
                lines = [ln for ln in text.splitlines() if ln.strip()]
                errors = [ln for ln in lines if ln.startswith("error")]
                if len(errors) != 1 or lines[-1] != errors[0]:
                    cls.append("BADERR")
                    det.append(f"{len(errors)} `error` lines in {len(lines)} stderr lines"
                               + ("" if not errors or lines[-1] == errors[-1] else ", the error is not the last"))
                elif len(lines) > 1:
                    notes.append(f"{len(lines) - 1} stderr lines of work before the error")
        cls.sort(key=SEVERITY.index)
        if not cls:
            answered = rc == 0 or rc in case.ok_rcs or (case.stdout == "closed" and rc in (141, -signal.SIGPIPE))
            cls = ["ok" if answered else "refused"]
        return cls, det, notes

    def check_output(self, case, work, resolved, so, reader) -> Optional[str]:
        if case.validate is None or case.out is None:
            return None
        if case.data_at == "none":
            return None
        if case.out_kind == "dir":
            if not resolved:
                return None
            return case.validate(Path(resolved))
        if case.data_at == "fifo":
            data = bytes(reader.data) if reader else b""
            return case.validate(data) if data else "nothing arrived through the FIFO"
        if case.data_at == "stdout":
            return case.validate(last_json(so) if case.validate.__qualname__.startswith("json_with") else so)
        if case.data_at == "capture":
            path = work / case.stdout[5:]
            data = path.read_bytes() if path.exists() else b""
            return case.validate(last_json(data) if case.validate.__qualname__.startswith("json_with") else data)
        if not resolved or not os.path.isfile(resolved):
            return f"no output file at {os.path.relpath(resolved, work) if resolved else case.out!r}"
        with open(resolved, "rb") as f:
            return case.validate(f.read())

    def cleanup(self, cdir: Path):
        def onerror(func, path, exc):
            try:
                os.chmod(os.path.dirname(path), 0o755)
                func(path)
            except OSError:
                pass
        shutil.rmtree(cdir, onerror=onerror)


def key_line(lines: list) -> str:
    """The telling stderr line: the panic, else the error, else the first."""
    for want in ("panicked", "error"):
        for ln in lines:
            if want in ln[:80]:
                return ln
    return lines[0] if lines else ""


def last_json(data: bytes) -> bytes:
    """The JSON document in a stream that may hold a readable report before or after it (an
    output written through /dev/stdout shares the stream with the command's report): the
    first object or array that starts a line and parses whole."""
    text = data.decode(errors="replace")
    starts = ([0] if text[:1] in ("{", "[") else []) + [
        i + 1 for i in range(len(text) - 1) if text[i] == "\n" and text[i + 1] in ("{", "[")
    ]
    dec = json.JSONDecoder()
    for j in starts:
        try:
            _, end = dec.raw_decode(text, j)
        except ValueError:
            continue
        return text[j:end].encode()
    return data


def replaced_what(e: dict, a: Optional[dict]) -> Optional[str]:
    if a is None:
        return f"{kind_name(e['fmt'])} removed"
    if a["fmt"] != e["fmt"]:
        return f"{kind_name(e['fmt'])} became a {kind_name(a['fmt'])}"
    if e["fmt"] == stat.S_IFLNK and a.get("link") != e.get("link"):
        return f"symlink retargeted {e.get('link')!r} -> {a.get('link')!r}"
    if e["fmt"] in (stat.S_IFCHR, stat.S_IFBLK) and a["rdev"] != e["rdev"]:
        return "device number changed"
    if a["ino"] != e["ino"] or a["dev"] != e["dev"]:
        return f"{kind_name(e['fmt'])} replaced by a new one (inode changed)"
    return None


def signal_name(sig: int) -> str:
    try:
        return signal.Signals(sig).name
    except ValueError:
        return str(sig)


def killpg(pid: int):
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def root_can_rofs(base: Path) -> bool:
    if os.geteuid() != 0 or not shutil.which("unshare"):
        return False
    d = base / "_rofs-check"
    d.mkdir(exist_ok=True)
    r = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c",
                        'mount --bind "$1" "$1" && mount -o remount,bind,ro "$1" && ! touch "$1/x" 2>/dev/null',
                        "sh", str(d)], capture_output=True)
    ok = r.returncode == 0 and not (d / "x").exists()
    shutil.rmtree(d, ignore_errors=True)
    return ok


def driverless_major_free() -> bool:
    try:
        text = Path("/proc/devices").read_text()
    except OSError:
        return False
    return not re.search(r"^\s*240\s", text, re.M)


# --------------------------------------------------------------------------------------------
# Caches and the main program


def build_cache(binary: str, cache: Path):
    cache.mkdir(exist_ok=True)
    rec_rows = REC_CSV.read_text().splitlines()[1:]
    n = 2_000_000
    with open(cache / "rec-2e6.csv", "w") as f:
        f.write("t,w,y\n")
        vals = [r.split(",", 1)[1] for r in rec_rows]
        step = 0.005
        chunk = []
        for k in range(n):
            chunk.append(f"{k * step:.6f},{vals[k % len(vals)]}\n")
            if len(chunk) == 100_000:
                f.write("".join(chunk))
                chunk = []
        f.write("".join(chunk))
    with open(cache / "input-2e6.csv", "w") as f:
        f.write("t,w\n")
        f.write("".join(f"{k * 1e-3:.6f},{(k % 1000) * 1e-3:.3f}\n" for k in range(n)))
    tel = TEL_CSV.read_text().splitlines()
    head, rows = tel[0], tel[1:]
    tails = [r.split(",", 1)[1] for r in rows]
    with open(cache / "tel-5e5.csv", "w") as f:
        f.write(head + "\n")
        buf = []
        for k in range(500_000):
            ms = k * 100
            h, rem = divmod(ms // 1000, 3600)
            m, s = divmod(rem, 60)
            buf.append(f"2025-11-09T{h % 24:02d}:{m:02d}:{s:02d}.{ms % 1000:03d}Z,{tails[k % len(tails)]}\n")
            if len(buf) == 50_000:
                f.write("".join(buf))
                buf = []
        f.write("".join(buf))
    # a sweep and its shards, made by the binary under test
    tmp = cache / "sweepwork"
    tmp.mkdir(exist_ok=True)
    shutil.copyfile(W_TOML, tmp / "w.toml")
    (tmp / "s.toml").write_text(SWEEP_SPEC)
    ok = True
    for args in (["--out", "sw"], ["--out", "shards", "--shard", "0/2"], ["--out", "shards", "--shard", "1/2"]):
        r = subprocess.run([binary, "sweep", "s.toml", "-q", *args], cwd=tmp, capture_output=True, timeout=60)
        ok &= r.returncode == 0
        if r.returncode != 0:
            print(f"warning: cache sweep {args} failed: {r.stderr.decode(errors='replace')[:200]}", file=sys.stderr)
    if (tmp / "sw").is_dir():
        shutil.move(str(tmp / "sw"), str(cache / "sw"))
    if (tmp / "shards").is_dir():
        shutil.move(str(tmp / "shards"), str(cache / "shards"))
    shutil.rmtree(tmp, ignore_errors=True)


def all_cases() -> list:
    cases = writer_cases() + input_cases()
    for i, c in enumerate(cases):
        c.id = f"c{i:04d}"
    return cases


def summarize(results: list) -> str:
    classes = CLEAN + SEVERITY + ["skipped"]
    present = [c for c in classes if any(c in r["classes"] for r in results) or c in ("ok", "refused")]
    cmds = sorted({r["command"] for r in results})
    w = max(len(c) for c in cmds + ["command", "total"]) + 2
    lines = [f"{'command':<{w}}" + "".join(f"{c:>12}" for c in present) + f"{'cases':>8}"]
    for cmd in cmds + ["total"]:
        rs = results if cmd == "total" else [r for r in results if r["command"] == cmd]
        row = f"{cmd:<{w}}"
        for c in present:
            n = sum(1 for r in rs if c in r["classes"])
            row += f"{n if n else '.':>12}"
        lines.append(row + f"{len(rs):>8}")
    lines.append("(a case counts under every class it hits; clean = ok + refused with no other class)")
    return "\n".join(lines)


def render_cmd(argv: list) -> str:
    s = " ".join(shlex.quote(a) for a in argv)
    return s if len(s) <= 220 else s[:220] + "..."


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=str(REPO / "target/release/moreau"))
    ap.add_argument("--json", help="write every result here")
    ap.add_argument("--keep", action="store_true", help="keep the directories of non-clean cases")
    ap.add_argument("--filter", help="only cases whose command or target contains this")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--self-test", action="store_true", help="run the fake binaries (negative controls)")
    ap.add_argument("--timeout-scale", type=float, default=1.0, help=argparse.SUPPRESS)
    a = ap.parse_args()
    os.umask(0o022)
    if a.self_test:
        sys.exit(self_test())
    cases = all_cases()
    if a.filter:
        cases = [c for c in cases if a.filter in c.command or a.filter in c.target]
    if a.list:
        for c in cases:
            print(f"{c.id}  {c.command:<30} {c.target:<45} expect {c.expect}")
        print(f"{len(cases)} cases")
        return
    binary = os.path.abspath(a.bin)
    if not os.access(binary, os.X_OK):
        sys.exit(f"error: {binary} is not an executable")
    base = Path(tempfile.mkdtemp(prefix="moreau-probe-"))
    os.chmod(base, 0o755)
    cache = base / "_cache"
    results = []
    t0 = time.monotonic()
    try:
        print(f"building inputs in {base} ...", file=sys.stderr)
        build_cache(binary, cache)
        prober = Prober(binary, base, cache, a.keep, a.timeout_scale)
        if not prober.can_rofs:
            print("note: no read-only bind mounts here (not root?): 0555 directories instead", file=sys.stderr)
        if not driverless_major_free():
            print("note: major 240 has a driver here: device-node cases are skipped", file=sys.stderr)
            cases = [c for c in cases if "no driver" not in c.target]
        for i, c in enumerate(cases):
            r = prober.run(c)
            results.append(r)
            mark = "." if r["cls"] in CLEAN else ("s" if r["cls"] == "skipped" else "!")
            print(mark, end="", file=sys.stderr, flush=True)
            if (i + 1) % 100 == 0:
                print(f" {i + 1}", file=sys.stderr, flush=True)
        print(file=sys.stderr)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
        if not a.keep:
            shutil.rmtree(base, ignore_errors=True)
    total = time.monotonic() - t0
    bad = [r for r in results if r["cls"] not in CLEAN + ["skipped"]]
    print(f"moreau hostile probe: {len(results)} cases, binary {binary}, {total:.0f} s")
    print(summarize(results))
    slow = sorted(results, key=lambda r: -r.get("time", 0))[:5]
    print("slowest: " + ", ".join(f"{r['id']} {r['command']} / {r['target']} {r['time']} s" for r in slow))
    skipped = [r for r in results if r["cls"] == "skipped"]
    for r in skipped:
        print(f"skipped {r['id']} {r['command']} / {r['target']}: {r['detail']}")
    noted = [r for r in results if r["cls"] in CLEAN and (r.get("notes") or r.get("time", 0) > 3)]
    print(f"\nnotes on clean cases: {len(noted)}")
    for r in noted:
        what = "; ".join(r.get("notes") or []) or "slow"
        print(f"  {r['id']} [{r['cls']}] {r['command']} / {r['target']}: rc {r['rc']}, {r['time']} s; {what}")
    print(f"\nnon-clean cases: {len(bad)}")
    for r in bad:
        print(f"- {r['id']} [{'/'.join(r['classes'])}] {r['command']} / {r['target']} (expect {r['expect']}): "
              f"rc {r['rc']}, {r['time']} s; {r['detail']}")
        print(f"    $ moreau {render_cmd(r['argv'])}")
        if r.get("stderr_key"):
            print(f"    stderr: {r['stderr_key'][:240]}")
    if a.json:
        Path(a.json).write_text(json.dumps({"binary": binary, "cases": len(results), "seconds": round(total, 1),
                                            "results": results}, indent=1))
    sys.exit(1 if bad else 0)


# --------------------------------------------------------------------------------------------
# Self-test: fake binaries that misbehave must be classified as they misbehave

FAKE = r"""#!/bin/sh
out=""; prev=""
for a in "$@"; do [ "$prev" = "--out" ] && out="$a"; prev="$a"; done
case "$PROBE_FAKE" in
good) printf '{"theta": 1}\n' > "$out"; exit 0;;
refuse) echo "error: refusing $out" >&2; exit 2;;
replace) rm -f "$out"; printf '{"theta": 1}\n' > "$out"; exit 0;;
panic) echo "thread 'main' panicked at src/main.rs:1:1:" >&2; echo "boom" >&2; exit 101;;
abort) kill -ABRT $$;;
segv) kill -SEGV $$;;
sleep) sleep 30; exit 0;;
overwrite) printf 'garbage' > w.toml; printf '{"theta": 1}\n' > "$out"; exit 0;;
leftover) printf '{"theta": 1}\n' > "$out"; : > .out.json.tmpAbC; exit 0;;
bigerr) printf 'error: %05000d\n' 0 >&2; exit 2;;
multiline) printf 'error: one\nerror: two\n' >&2; exit 2;;
accept) exit 0;;
clobber) rm -rf "$out"; mkdir -p "$out"; : > "$out/trajectory.csv"; exit 0;;
dgood) mkdir -p "$out"; : > "$out/trajectory.csv"; exit 0;;
dreplace) rm -f "$out"; mkdir -p "$out"; : > "$out/trajectory.csv"; exit 0;;
garbage) printf 'not json' > "$out"; exit 0;;
mess) mkdir partial; echo "error: failed half-way" >&2; exit 2;;
esac
exit 3
"""


def self_test() -> int:
    base = Path(tempfile.mkdtemp(prefix="moreau-probe-selftest-"))
    os.chmod(base, 0o755)
    fake = base / "fake.sh"
    fake.write_text(FAKE)
    os.chmod(fake, 0o755)
    fw = Writer("fake theta --out", "file", setup_w, ["w.toml"], lambda t: ["theta", "w.toml", "--out", t],
                json_with("theta"))
    dw = Writer("fake simulate --out", "dir", setup_w, ["w.toml"], lambda t: ["simulate", "w.toml", "--out", t],
                dir_with("trajectory.csv"), first="trajectory.csv")
    ft = {t.label: t for t in file_targets(fw)}
    dt = {t.label: t for t in dir_targets(dw)}
    plan = [
        (fw, ft, "good", "new file", "ok"),
        (fw, ft, "good", "/dev/null", "ok"),
        (fw, ft, "good", "symlink to a file", "ok"),
        (fw, ft, "good", "symlink chain", "ok"),
        (fw, ft, "good", "FIFO with a reader", "ok"),
        (fw, ft, "refuse", "the input itself", "refused"),
        (fw, ft, "refuse", "new file", "WRONG"),
        (fw, ft, "accept", "new file", "WRONG"),
        (fw, ft, "garbage", "new file", "WRONG"),
        (fw, ft, "accept", "the input itself", "WRONG"),
        (fw, ft, "replace", "symlink to a file", "REPLACED"),
        (fw, ft, "replace", "symlink to /dev/null", "REPLACED"),
        (fw, ft, "replace", "FIFO with a reader", "REPLACED"),
        (fw, ft, "replace", "unix socket", "REPLACED"),
        (fw, ft, "good", "the input itself", "OVERWRITTEN"),
        (fw, ft, "good", "symlink to the input", "OVERWRITTEN"),
        (fw, ft, "overwrite", "new file", "OVERWRITTEN"),
        (fw, ft, "panic", "new file", "PANIC"),
        (fw, ft, "abort", "new file", "ABORT"),
        (fw, ft, "segv", "new file", "ABORT"),
        (fw, ft, "sleep", "new file", "TIMEOUT"),
        (fw, ft, "good", "FIFO without a reader", "TIMEOUT"),
        (fw, ft, "leftover", "new file", "LEFTOVER"),
        (fw, ft, "bigerr", "the input itself", "BIGERR"),
        (fw, ft, "multiline", "the input itself", "BADERR"),
        (fw, ft, "good", "parent is a regular file", "WRONG"),  # printf fails, the script still exits 0
        (fw, ft, "mess", "the input itself", "LEFTOVER"),
        (dw, dt, "dgood", "new directory", "ok"),
        (dw, dt, "dgood", "symlink to a directory", "ok"),
        (dw, dt, "dreplace", "symlink to a directory", "REPLACED"),
        (dw, dt, "clobber", "directory with a foreign file", "CLOBBERED"),
        (dw, dt, "dgood", "regular file", "BADERR"),  # `: >` fails fatally: rc 2, two lines from the shell
    ]
    failures = 0
    prober = Prober(str(fake), base, base / "_cache", keep=False, timeout_scale=0.2)
    for i, (w, targets, mode, label, want) in enumerate(plan):
        case = target_case(w, targets[label])
        case.id = f"s{i:03d}"
        case.env = {"PROBE_FAKE": mode}
        r = prober.run(case)
        got = r["cls"]
        ok = got == want
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} {mode:<10} {label:<32} -> {got:<12} (want {want}) {r.get('detail', '')}")
    shutil.rmtree(base, ignore_errors=True)
    print(f"self-test: {len(plan) - failures}/{len(plan)} classified as they must be")
    return 1 if failures else 0


if __name__ == "__main__":
    main()
