"""The guide (docs/, mkdocs.yml) and README.md: the guide builds without warnings, and
every command they show runs, so neither can drift from the program (issue 43).

- test_guide_builds: scripts/build-docs.sh OUTDIR (pdoc's API reference of the installed
  module `heron`, then `mkdocs build --strict`) succeeds and prints no warning; the API
  reference carries the stubs' signatures and the docstrings; every chapter is in the nav.
- test_readme_fits_one_screen_and_links_resolve: README.md has at most 200 lines, opens
  with the two commands, and its relative links name files that exist.
- test_commands_run[FILE]: every command of FILE runs, in the order FILE shows them, in
  one working folder per file (a copy of scenes/, lenses/, examples/ and spectra/, and an
  empty docs/images/ for the commands that write a figure there), with `heron` on PATH
  (HERON_BIN, default target/release/heron). The commands are:
  - every line of a fenced ```sh block (lines ending in a backslash joined to the next;
    blank lines and `#` comment lines skipped); each must exit with status 0;
  - every `$ ` line of any other fenced block (a transcript); where the transcript shows
    `$ echo $?` and a number, the command before must exit with that status, else 0;
  - README.md's ```python blocks (the first render from Python), run as a script by this
    interpreter.
  A command that cannot run here is in SKIPPED with the reason; the test fails on a SKIPPED
  entry that no file shows any more. A block that is not ```sh may show `heron` only as a
  synopsis (a placeholder in capitals, options in brackets or alternatives with |), so a
  command cannot hide from the test in a ```text block.

Reduced settings (stated in docs/testing.md too), so that the commands take minutes, not
hours; what a command prints is not compared, only its exit status:
  - `heron render`: --spp 4 (the command's own --spp if lower), replacing the command's
    --spp or added to it (the scene's own spp otherwise); size and everything else as shown;
  - `heron converge`: --reference-spp 16 at most, each --spp value capped at 4;
  - `heron stress`: --rays 1000 (the command's own --rays if lower);
  - `heron sky lee`: --radii 4 at most;
  - `python` and `.venv/bin/python` at the start of a command: this interpreter;
  - `heron view` and `heron render --view` (servers that run until Ctrl-C): started with
    --no-browser; the test waits for the address they print (and, for a render, for the
    finished file in the viewer), asks the server for /api/images, which must list the
    images, and then stops it with SIGINT.

Time: about 80 s on the 2-core machine (measured below).
"""
from __future__ import annotations

import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

import pytest

from heronrun import REPO, require_heron_bin

DOCS = REPO / "docs"
README = REPO / "README.md"
SOURCES = [README, *sorted(DOCS.glob("*.md"))]

# Measured (2026-12-07, the 2-core machine shared with another engineer's work): the
# whole file took 73-78 s, the guide's build about 1.5 s of it; the slowest commands are
# the pool and the polarised rainbow (10 s each, mostly the scene's set-up: the waves'
# mesh, the sky's table) and `heron sky lee` (6 s at 4 radii). A command that hangs fails
# after this long rather than eating CI's budget.
COMMAND_TIMEOUT_S = 120

# Commands that cannot run in the test, with why. The key is the command as the guide
# shows it (continuation lines joined, whitespace runs as one space, comment removed).
SKIPPED = {
    "scripts/setup.sh":
        "the set-up itself (apt, the venv, the build): the test runs inside what it made",
    "scripts/test.sh":
        "the test command itself, which runs this test",
    "pip install heron-0.1.0-cp39-abi3-manylinux_2_35_x86_64.whl":
        "the wheel is built by scripts/build-wheel.sh; tests/python/test_dist.py installs "
        "each wheel into a fresh venv and renders with it",
    "tar xzf heron-0.1.0-linux-x86_64.tar.gz":
        "the tarball is built by scripts/build-dist.sh; tests/python/test_dist.py unpacks "
        "it, moves it and renders with its binary",
    "heron-0.1.0-linux-x86_64/bin/heron render heron-0.1.0-linux-x86_64/scenes/default.toml "
    "-o default.exr":
        "the unpacked tarball's binary: tests/python/test_dist.py renders this scene with it "
        "and compares the bytes",
    "cd /shared/$USER && tar xzf heron-0.1.0-linux-x86_64.tar.gz":
        "a real cluster's shared file system",
    "HERON_BIN=$PWD/heron-0.1.0-linux-x86_64/bin/heron "
    "heron-0.1.0-linux-x86_64/deploy/slurm/submit.sh "
    "heron-0.1.0-linux-x86_64/scenes/rainbow-descartes.toml 16 /shared/runs/bow "
    "--spp 65536 --seed 3":
        "sbatch on a real cluster; tests/python/test_slurm.py submits the unpacked "
        "tarball's submit.sh to a single-node Slurm",
    "squeue -j 4711,4712":
        "the job ids of a real cluster",
    'eval "$(tests/slurm/cluster.sh start)"':
        "starts munged, slurmctld and slurmd as root; tests/python/test_slurm.py does "
        "exactly these steps",
    "HERON_BIN=$PWD/target/release/heron deploy/slurm/submit.sh "
    "scenes/caustic-dispersion.toml 4 /tmp/run --spp 64":
        "needs the cluster above; tests/python/test_slurm.py runs it",
    "squeue; scontrol show job <id>":
        "needs the cluster above; <id> is the job's",
    'tests/slurm/cluster.sh stop "$HERON_SLURM_DIR"':
        "needs the cluster above",
    "docker build -f deploy/k8s/Dockerfile -t heron:latest .":
        "no Docker in CI; tests/python/test_slurm.py runs the manifest's commands locally",
    "kubectl apply -f deploy/k8s/render-job.yaml":
        "no Kubernetes cluster in CI; tests/python/test_slurm.py parses the manifest and "
        "runs its containers' commands for every index",
    "kubectl wait --for=condition=complete --timeout=24h job/heron-merge":
        "no Kubernetes cluster in CI",
    "cargo install cargo-fuzz --locked":
        "downloads and builds cargo-fuzz; fuzzing needs the nightly toolchain",
    "cd fuzz":
        "the fuzzing commands' folder; the commands after it are skipped",
    "cargo +nightly fuzz run -a scene_toml -- -max_total_time=1200 -timeout=10 "
    "-rss_limit_mb=2048 -malloc_limit_mb=1024 -dict=dict/scene_toml.dict":
        "nightly toolchain, 20 minutes; the test command replays the corpus instead "
        "(tests/fuzz_corpus.rs)",
    "cargo +nightly fuzz cmin -a scene_toml -- -use_counters=0":
        "nightly toolchain; minimises the corpus before committing it",
    "HERON_EMBREE4_LIB=$(echo $PWD/.venv/lib/python3*/site-packages/embreex.libs) "
    "CARGO_TARGET_DIR=target/embree4 cargo build --release":
        "a second release build (minutes); scripts/test.sh builds and tests it",
    "target/embree4/release/heron bench traversal --mesh bumpy.obj --eye 0,0.3,3 "
    "--look-at 0,0,0 --raw":
        "needs the Embree 4 build above; tests/bench_traversal.rs runs the raw comparison "
        "on both builds",
}

COPIED = ("scenes", "lenses", "examples", "spectra")
RENDER_SPP = 4
CONVERGE_REFERENCE_SPP = 16
CONVERGE_SPP = 4
STRESS_RAYS = 1000
LEE_RADII = 4

FENCE = re.compile(r"^(\s*)```(\S*)")
# A usage synopsis: a placeholder in capitals (SCENE.toml, OUT.exr, NM), options in
# brackets, or alternatives.
SYNOPSIS = re.compile(r"\[|\||\b[A-Z][A-Z0-9_]*\b")


class Command:
    def __init__(self, path, line, text, kind, status=0):
        self.path, self.line, self.text, self.kind, self.status = path, line, text, kind, status

    def where(self) -> str:
        return f"{self.path.relative_to(REPO)}:{self.line}"


def blocks(path: pathlib.Path):
    """(line of the opening fence, language, lines) of every fenced block; fails on a fence
    indented into a list item, which MkDocs (Python-Markdown) does not render as code."""
    out, lang, start, body = [], None, 0, []
    for n, line in enumerate(path.read_text().split("\n"), 1):
        m = FENCE.match(line)
        if lang is None and m:
            assert not m.group(1), f"{path.name}:{n}: an indented fence is not code in MkDocs"
            lang, start, body = m.group(2), n, []
        elif lang is not None and line.strip() == "```":
            out.append((start, lang, body))
            lang = None
        elif lang is not None:
            body.append(line)
    assert lang is None, f"{path.name}: a fence opened at line {start} is never closed"
    return out


def normalise(cmd: str) -> str:
    """Comment removed (` # ...`; no command here has a # inside quotes) and whitespace
    runs as one space: the form SKIPPED keys use."""
    cmd = re.sub(r"(^|\s)#(\s.*)?$", "", cmd)
    return " ".join(cmd.split())


def commands(path: pathlib.Path) -> list[Command]:
    out = []
    for start, lang, body in blocks(path):
        if lang == "sh":
            joined, first = "", None
            for k, line in enumerate(body):
                if first is None:
                    first = start + 1 + k
                if line.rstrip().endswith("\\"):
                    joined += line.rstrip()[:-1] + " "
                    continue
                joined += line
                text = normalise(joined)
                if text:
                    out.append(Command(path, first, text, "sh"))
                joined, first = "", None
            assert not joined, f"{path.name}:{start}: a continuation line ends the block"
        elif lang == "python" and path == README:
            out.append(Command(path, start, "\n".join(body), "python"))
        else:
            shown = [l for l in body if l.startswith("$ ")]
            for k, line in enumerate(body):
                if line.startswith("$ echo $?"):
                    assert out and out[-1].path == path and out[-1].kind == "transcript", \
                        f"{path.name}:{start + 1 + k}: `echo $?` after no command"
                    out[-1].status = int(body[k + 1].strip())
                elif line.startswith("$ "):
                    out.append(Command(path, start + 1 + k, normalise(line[2:]), "transcript"))
                elif not shown and line.startswith("heron "):
                    assert SYNOPSIS.search(line), (
                        f"{path.name}:{start + 1 + k}: `{line}` is a command in a ```{lang} "
                        f"block: fence it as ```sh so that the docs test runs it")
    return out


def _flag(cmd: str, flag: str, value) -> str:
    """cmd with `flag value` in place of the flag's own value, or appended."""
    pattern = re.compile(rf"(\s){re.escape(flag)}(\s+|=)\S+")
    if pattern.search(cmd):
        return pattern.sub(rf"\g<1>{flag} {value}", cmd)
    return f"{cmd} {flag} {value}"


def _own(cmd: str, flag: str):
    m = re.search(rf"\s{re.escape(flag)}(?:\s+|=)(\S+)", cmd)
    return m.group(1) if m else None


def reduced(cmd: str) -> str:
    """The command at the reduced settings of the module's docstring."""
    if cmd.startswith("heron render "):
        own = _own(cmd, "--spp")
        return _flag(cmd, "--spp", min(int(own), RENDER_SPP) if own else RENDER_SPP)
    if cmd.startswith("heron converge "):
        own = _own(cmd, "--reference-spp")
        cmd = _flag(cmd, "--reference-spp",
                    min(int(own), CONVERGE_REFERENCE_SPP) if own else CONVERGE_REFERENCE_SPP)
        own = _own(cmd, "--spp")
        values = [int(v) for v in own.split(",")] if own else [CONVERGE_SPP]
        capped = sorted({min(v, CONVERGE_SPP) for v in values})
        return _flag(cmd, "--spp", ",".join(map(str, capped)))
    if cmd.startswith("heron stress "):
        own = _own(cmd, "--rays")
        return _flag(cmd, "--rays", min(int(own), STRESS_RAYS) if own else STRESS_RAYS)
    if cmd.startswith("heron sky lee "):
        own = _own(cmd, "--radii")
        return _flag(cmd, "--radii", min(int(own), LEE_RADII) if own else LEE_RADII)
    return re.sub(r"^(\.venv/bin/)?python(3)? ", f"{sys.executable} ", cmd)


def _is_server(cmd: str) -> bool:
    return cmd.startswith("heron view ") or (cmd.startswith("heron render ")
                                             and re.search(r"\s--view(\s|$)", cmd) is not None)


def _run_server(shown: str, work, env) -> tuple[int, str]:
    """A viewer command (see the module's docstring): (0 when it served its images, else
    1; what it printed)."""
    import json
    import signal
    import urllib.request

    proc = subprocess.Popen(["bash", "-c", f"exec {shown} --no-browser"], cwd=work, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        m = re.search(r"http://127\.0\.0\.1:\d+/", line)
        if not m:
            return 1, line + proc.stderr.read()
        if shown.startswith("heron render "):
            err = ""
            while "the viewer shows" not in err:
                more = proc.stderr.readline()
                if not more:
                    return 1, err
                err += more
        with urllib.request.urlopen(m.group(0) + "api/images", timeout=30) as r:
            images = json.load(r)["images"]
        return (0 if images else 1), json.dumps([i["name"] for i in images])
    finally:
        # Both servers end on Ctrl-C with status 0 (their handlers also catch a SIGINT
        # that came in ignored, as in a background job of a non-interactive shell).
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            raise AssertionError(f"`{shown}` did not end on SIGINT")


def _workdir(tmp_path: pathlib.Path) -> pathlib.Path:
    work = tmp_path / "work"
    work.mkdir()
    for name in COPIED:
        shutil.copytree(REPO / name, work / name)
    (work / "docs" / "images").mkdir(parents=True)
    return work


def _env(tmp_path: pathlib.Path) -> dict:
    """PATH with a folder holding `heron` (a link to the binary under test) first."""
    bindir = tmp_path / "bin"
    bindir.mkdir()
    (bindir / "heron").symlink_to(require_heron_bin())
    env = dict(os.environ)
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"
    return env


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(REPO)))
def test_commands_run(path, tmp_path):
    cmds = [c for c in commands(path) if c.kind == "python" or c.text not in SKIPPED]
    if not cmds:
        return
    work, env = _workdir(tmp_path), _env(tmp_path)
    times = []
    for c in cmds:
        if c.kind == "python":
            script = tmp_path / f"block-{c.line}.py"
            script.write_text(c.text)
            argv, shown = [sys.executable, str(script)], "python block"
        else:
            shown = reduced(c.text)
            argv = ["bash", "-o", "pipefail", "-c", shown]
        t0 = time.monotonic()
        if c.kind != "python" and _is_server(shown):
            status, printed = _run_server(shown, work, env)
            times.append((time.monotonic() - t0, shown))
            if status != 0:
                pytest.fail(f"{c.where()}: `{shown}` served no images:\n{printed[-3000:]}",
                            pytrace=False)
            continue
        try:
            proc = subprocess.run(argv, cwd=work, env=env, capture_output=True, text=True,
                                  timeout=COMMAND_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{c.where()}: `{shown}` took over {COMMAND_TIMEOUT_S} s", pytrace=False)
        times.append((time.monotonic() - t0, shown))
        if proc.returncode != c.status:
            pytest.fail(
                f"{c.where()}: `{shown}` exited with status {proc.returncode}, expected "
                f"{c.status}\n--- stderr\n{proc.stderr[-3000:]}\n--- stdout\n"
                f"{proc.stdout[-2000:]}", pytrace=False)
    for seconds, shown in sorted(times, reverse=True)[:5]:
        print(f"{seconds:6.1f} s  {shown[:100]}")


def test_skipped_commands_are_still_shown():
    shown = {c.text for p in SOURCES for c in commands(p)}
    stale = sorted(set(SKIPPED) - shown)
    assert not stale, f"SKIPPED names commands no file shows any more: {stale}"


def test_reduced_settings():
    assert reduced("heron render a.toml -o a.exr --spp 64 --seed 1") == \
        "heron render a.toml -o a.exr --spp 4 --seed 1"
    assert reduced("heron render a.toml -o a.exr") == "heron render a.toml -o a.exr --spp 4"
    assert reduced("heron render a.toml --spp 2 -o a.exr") == "heron render a.toml --spp 2 -o a.exr"
    assert reduced("heron converge a.toml --reference-spp 8192 --spp 1,4,16,64") == \
        "heron converge a.toml --reference-spp 16 --spp 1,4"
    assert reduced("heron stress a.toml --integrator path") == \
        "heron stress a.toml --integrator path --rays 1000"
    assert reduced("heron sky lee --radii 24 -o lee.csv") == "heron sky lee --radii 4 -o lee.csv"
    assert reduced(".venv/bin/python x.py --out y.png") == f"{sys.executable} x.py --out y.png"


def test_readme_fits_one_screen_and_links_resolve():
    text = README.read_text()
    assert len(text.splitlines()) <= 200, "README.md is over 200 lines: move text to docs/"
    first = blocks(README)[0]
    assert [normalise(l) for l in first[2]] == ["scripts/setup.sh", "scripts/test.sh"], \
        "README.md's first code block must be the two commands"
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" not in target:
            assert (REPO / target).exists(), f"README.md links to {target}, which is missing"


def test_guide_builds(tmp_path):
    """scripts/build-docs.sh: pdoc, then mkdocs build --strict; no warning anywhere."""
    out = tmp_path / "site"
    env = dict(os.environ, PYTHON=sys.executable)
    proc = subprocess.run(["bash", str(REPO / "scripts" / "build-docs.sh"), str(out)],
                          cwd=REPO, env=env, capture_output=True, text=True, timeout=600)
    log = proc.stdout + proc.stderr
    assert proc.returncode == 0, f"build-docs.sh failed:\n{log[-5000:]}"
    warnings = [l for l in log.splitlines() if re.search(r"warn", l, re.IGNORECASE)]
    assert not warnings, "the guide's build warned:\n" + "\n".join(warnings)
    for page in SOURCES[1:]:
        assert (out / page.with_suffix(".html").name).is_file(), f"{page.name} was not built"
    api = (out / "api" / "heron.html").read_text()
    # The stub's signatures and the docstrings (heron/__init__.pyi beside the module).
    for expected in ("load_scene", "RenderResult", "sky_profile", "HeronError",
                     "Image width in pixels"):
        assert expected in api, f"the API reference lacks {expected!r}"
    nav = (REPO / "mkdocs.yml").read_text()
    for page in SOURCES[1:]:
        assert re.search(rf":\s*{re.escape(page.name)}\s*$", nav, re.MULTILINE), \
            f"{page.name} is not in mkdocs.yml's nav"
