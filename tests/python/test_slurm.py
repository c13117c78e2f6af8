"""heron on a cluster (issue 11, part 3): a sharded render submitted to a real Slurm, and
the Kubernetes recipe's scripts.

The Slurm tests start a single-node Slurm cluster on this machine from Debian's packages
(tests/slurm/cluster.sh: munged, slurmctld and slurmd in a temporary directory, found
through SLURM_CONF), submit deploy/slurm/submit.sh's job array and dependent merge with
sbatch, wait for them, and compare the merged EXR's bytes with one `heron render` of the
same scene and settings. The sharded render runs as a user without root would (issue 26):
from the relocatable tarball of scripts/build-dist.sh, unpacked (conftest.py's
dist_unpacked), with the tarball's submit.sh, binary and scene. The cluster is stopped and its directory removed when the module
ends, whether the tests passed or not.

They need root (slurmd starts jobs as the submitting user) and the packages slurm-wlm and
munge (scripts/setup.sh --deps installs them). In CI (CI set) or as root a missing
package fails the test; only a non-root run outside CI skips it, saying why.

The other tests need no Slurm: deploy/slurm's scripts run as plain shell scripts with the
environment Slurm would give them (merge.sbatch naming a missing part, render-array.sbatch
refusing a task that is not a shard), and the Kubernetes manifest (deploy/k8s) is parsed
and its render and merge commands run locally for every completion index.
"""
from __future__ import annotations

import json
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import time

import pytest

from heronrun import REPO, require_heron_bin

CLUSTER = REPO / "tests" / "slurm" / "cluster.sh"
SLURM_DIR = REPO / "deploy" / "slurm"
K8S_MANIFEST = REPO / "deploy" / "k8s" / "render-job.yaml"
SLURM_TOOLS = ("munged", "mungekey", "slurmctld", "slurmd", "sbatch", "squeue", "scontrol",
               "sinfo", "scancel")

# The scene of the Slurm run: bidirectional path tracing (its light subpaths splat into
# other pixels, the hardest case for a sample split) through a dispersive prism. 6 spp in
# 4 shards: shards of unequal sample counts if the split is by sample index. About 2 s of
# rendering in all on one core.
SLURM_SCENE = REPO / "scenes" / "caustic-dispersion.toml"
SLURM_SHARDS = 4
SLURM_FLAGS = ("--spp", "6", "--seed", "11")

# A cheap scene (64x48) for the tests of the scripts themselves.
SMALL_SCENE = REPO / "tests" / "python" / "scenes" / "quad_oblique.toml"
SMALL_FLAGS = ("--spp", "5", "--seed", "3")

# Generous bounds on waiting (not measurements): a job array of 4 short renders and a merge
# take some 15 s on an idle 2-core machine, most of it Slurm's scheduling interval.
JOB_TIMEOUT_S = float(os.environ.get("HERON_SLURM_JOB_TIMEOUT", "600"))
TERMINAL_STATES = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY",
                   "PREEMPTED", "BOOT_FAIL", "DEADLINE"}


def _in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def _run(cmd, *, env=None, timeout=300, cwd=REPO) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, env=env,
                          timeout=timeout, cwd=cwd)


class Cluster:
    """A running tests/slurm/cluster.sh cluster: its directory and the environment that
    points the Slurm commands at it."""

    def __init__(self, directory: pathlib.Path, env: dict):
        self.dir = directory
        self.env = env

    def logs(self) -> str:
        proc = _run(["bash", CLUSTER, "logs", self.dir], env=self.env, timeout=60)
        return proc.stdout + proc.stderr

    def jobs(self, job_id: str) -> list[dict]:
        """scontrol's records of a job (one per array task once the array is split)."""
        proc = _run(["scontrol", "--oneliner", "show", "job", job_id], env=self.env,
                    timeout=60)
        if proc.returncode != 0:
            raise AssertionError(f"scontrol show job {job_id} failed: {proc.stderr.strip()}")
        records = []
        for line in proc.stdout.splitlines():
            if not line.strip():
                continue
            fields = dict(m.groups() for m in re.finditer(r"(\w+)=(\S*)", line))
            records.append(fields)
        return records

    def wait(self, job_ids: list[str], what: str, outdir: pathlib.Path) -> dict:
        """Polls scontrol until every record of every job is in a terminal state; returns
        {job_id: [records]}. Fails with the jobs, their output and the daemons' logs."""
        deadline = time.monotonic() + JOB_TIMEOUT_S
        while True:
            records = {j: self.jobs(j) for j in job_ids}
            if all(r and all(x.get("JobState") in TERMINAL_STATES for x in r)
                   for r in records.values()):
                return records
            if time.monotonic() > deadline:
                pytest.fail(f"{what}: jobs {job_ids} not finished after {JOB_TIMEOUT_S:.0f} s "
                            f"(HERON_SLURM_JOB_TIMEOUT)\n{self.report(job_ids, outdir)}",
                            pytrace=False)
            time.sleep(0.5)

    def report(self, job_ids: list[str], outdir: pathlib.Path) -> str:
        parts = []
        for j in job_ids:
            proc = _run(["scontrol", "show", "job", j], env=self.env, timeout=60)
            parts.append(f"--- scontrol show job {j} ---\n{proc.stdout}{proc.stderr}")
        for log in sorted((outdir / "logs").glob("*.out")) if (outdir / "logs").is_dir() else []:
            parts.append(f"--- {log} ---\n{log.read_text(errors='replace')[-3000:]}")
        parts.append(self.logs())
        return "\n".join(parts)


@pytest.fixture(scope="module")
def slurm():
    """A single-node Slurm cluster for this module, stopped (daemons killed, directory
    removed) at the end even when a test failed."""
    if os.geteuid() != 0:
        reason = ("the Slurm test needs root: slurmd starts jobs as the submitting user, "
                  "which only root may do (CI runs it as root)")
        if _in_ci():
            pytest.fail(reason, pytrace=False)
        pytest.skip(reason + "; run as root to include it")
    missing = [t for t in SLURM_TOOLS if shutil.which(t) is None]
    if missing:
        pytest.fail(f"Slurm/munge commands missing: {', '.join(missing)}. Install Debian's "
                    f"slurm-wlm and munge: scripts/setup.sh --deps", pytrace=False)
    proc = _run(["bash", CLUSTER, "start"], timeout=180)
    if proc.returncode != 0:
        pytest.fail(f"tests/slurm/cluster.sh start failed (status {proc.returncode}):\n"
                    f"{proc.stderr[-8000:]}\n{proc.stdout[-2000:]}", pytrace=False)
    exports = dict(re.findall(r"^export (\w+)=(.*)$", proc.stdout, re.M))
    directory = pathlib.Path(exports["HERON_SLURM_DIR"])
    env = dict(os.environ, SLURM_CONF=exports["SLURM_CONF"])
    try:
        yield Cluster(directory, env)
    finally:
        stop = _run(["bash", CLUSTER, "stop", directory], env=env, timeout=180)
        assert stop.returncode == 0, f"cluster.sh stop failed: {stop.stderr}"
        assert not directory.exists(), f"cluster.sh stop left {directory}"


def _submit(cluster: Cluster, scene, shards: int, outdir: pathlib.Path, flags, *,
            heron_bin=None, slurm_dir=SLURM_DIR) -> dict:
    env = dict(cluster.env, HERON_BIN=str(heron_bin or require_heron_bin()))
    proc = _run(["bash", slurm_dir / "submit.sh", scene, shards, outdir, *flags], env=env)
    assert proc.returncode == 0, f"submit.sh failed ({proc.returncode}): {proc.stderr}"
    ids = dict(re.findall(r"^(ARRAY_JOB|MERGE_JOB|OUTPUT)=(.*)$", proc.stdout, re.M))
    assert set(ids) == {"ARRAY_JOB", "MERGE_JOB", "OUTPUT"}, \
        f"submit.sh printed no job ids:\n{proc.stdout}"
    assert re.fullmatch(r"\d+", ids["ARRAY_JOB"]) and re.fullmatch(r"\d+", ids["MERGE_JOB"]), ids
    return ids


def _render_reference(scene, flags, out: pathlib.Path) -> pathlib.Path:
    out.parent.mkdir(parents=True, exist_ok=True)
    proc = _run([require_heron_bin(), "render", scene, "-o", out, *flags])
    assert proc.returncode == 0, f"reference render failed: {proc.stderr}"
    return out


def test_slurm_array_and_merge_equal_one_render(slurm, dist_unpacked, tmp_path):
    """The no-root path of the guide (docs/install.md): the relocatable tarball
    (scripts/build-dist.sh) unpacked, its own deploy/slurm/submit.sh, binary and scene;
    the merged image equals one render of the build tree's binary."""
    outdir = tmp_path / "run"
    heron_bin = dist_unpacked / "bin" / "heron"
    scene = dist_unpacked / "scenes" / SLURM_SCENE.name
    ids = _submit(slurm, scene, SLURM_SHARDS, outdir, SLURM_FLAGS, heron_bin=heron_bin,
                  slurm_dir=dist_unpacked / "deploy" / "slurm")
    array, merge = ids["ARRAY_JOB"], ids["MERGE_JOB"]
    records = slurm.wait([array, merge], "sharded render", outdir)

    def fail(msg):
        pytest.fail(f"{msg}\n{slurm.report([array, merge], outdir)}", pytrace=False)

    tasks = {int(r["ArrayTaskId"]): r["JobState"] for r in records[array]}
    if tasks != {k: "COMPLETED" for k in range(SLURM_SHARDS)}:
        fail(f"array job {array}: task states {tasks}, expected {SLURM_SHARDS} COMPLETED")
    if [r["JobState"] for r in records[merge]] != ["COMPLETED"]:
        fail(f"merge job {merge}: {[r['JobState'] for r in records[merge]]}")
    # The merge ran after the array, as the dependency says.
    if records[merge][0].get("Dependency") not in ("(null)", ""):
        fail(f"merge job {merge} still has a dependency: {records[merge][0]['Dependency']}")

    # The array and the merge ran the tarball's binary (submit.sh passes it on).
    for r in records[array] + records[merge]:
        assert str(dist_unpacked) in r.get("Command", ""), r.get("Command")
    # Each task rendered its own shard (the log line render-array.sbatch prints).
    for k in range(SLURM_SHARDS):
        log = outdir / "logs" / f"render-{array}_{k}.out"
        if not log.is_file() or f"heron shard {k}/{SLURM_SHARDS} " not in log.read_text():
            fail(f"{log} does not say it rendered shard {k}/{SLURM_SHARDS}")
        assert (outdir / f"part-{k}.heronfilm").is_file()

    merged = pathlib.Path(ids["OUTPUT"])
    assert merged == outdir.resolve() / "caustic-dispersion.exr"
    if not merged.is_file():
        fail(f"the merge job wrote no {merged}")
    ref = _render_reference(SLURM_SCENE, SLURM_FLAGS, tmp_path / "ref" / "single.exr")
    assert merged.read_bytes() == ref.read_bytes(), \
        "the EXR merged from the Slurm array differs from one heron render with all samples"
    assert merged.with_suffix(".png").read_bytes() == ref.with_suffix(".png").read_bytes(), \
        "the merged PNG preview differs from one heron render's"


def test_slurm_failed_shard_cancels_merge(slurm, tmp_path):
    """A task that fails (here: heron refuses --spp 0) leaves the merge never started:
    afterok is never satisfied and --kill-on-invalid-dep cancels it; the task's log holds
    heron's one-line error."""
    outdir = tmp_path / "bad"
    ids = _submit(slurm, SMALL_SCENE, 2, outdir, ("--spp", "0"))
    array, merge = ids["ARRAY_JOB"], ids["MERGE_JOB"]
    records = slurm.wait([array, merge], "failing render", outdir)
    states = sorted(r["JobState"] for r in records[array])
    merge_state = records[merge][0]["JobState"]
    report = slurm.report([array, merge], outdir)
    assert states == ["FAILED", "FAILED"], f"array tasks {states}\n{report}"
    assert merge_state == "CANCELLED", f"merge job {merge_state}\n{report}"
    log = (outdir / "logs" / f"render-{array}_0.out").read_text()
    assert "error: --spp: expected at least 1" in log, log
    assert not pathlib.Path(ids["OUTPUT"]).exists()
    assert not list(outdir.glob("*.heronfilm"))


# --- deploy/slurm's scripts outside Slurm -------------------------------------------------

def _script_env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}
    env["HERON_BIN"] = str(require_heron_bin())
    env.update({k: str(v) for k, v in extra.items()})
    return env


def _render_shard(outdir, k, n, scene=SMALL_SCENE, flags=SMALL_FLAGS, **env):
    return _run(["bash", SLURM_DIR / "render-array.sbatch", scene, outdir, *flags],
                env=_script_env(SLURM_ARRAY_TASK_ID=k, **env))


def test_merge_sbatch_names_a_missing_part(tmp_path):
    """merge.sbatch passes every part 0..N-1 to heron merge, so a missing one fails the
    merge (status 1) with heron's one-line message naming it, and no image is written;
    once the part is there the merge equals one render."""
    outdir = tmp_path / "parts"
    for k in (0, 1, 3):
        proc = _render_shard(outdir, k, 4, HERON_SHARDS=4)
        assert proc.returncode == 0, proc.stderr
    out = tmp_path / "merged.exr"
    proc = _run(["bash", SLURM_DIR / "merge.sbatch", outdir, 4, out, "--no-png"],
                env=_script_env())
    assert proc.returncode == 1, (proc.returncode, proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "part-2.heronfilm" in lines[0], proc.stderr
    assert not out.exists() and not list(tmp_path.glob("merged*"))

    # SLURM_ARRAY_TASK_COUNT gives N when HERON_SHARDS is not set.
    proc = _render_shard(outdir, 2, 4, SLURM_ARRAY_TASK_COUNT=4)
    assert proc.returncode == 0, proc.stderr
    proc = _run(["bash", SLURM_DIR / "merge.sbatch", outdir, 4, out, "--no-png"],
                env=_script_env())
    assert proc.returncode == 0, proc.stderr
    ref = _render_reference(SMALL_SCENE, (*SMALL_FLAGS, "--no-png"), tmp_path / "ref.exr")
    assert out.read_bytes() == ref.read_bytes()


def test_render_array_sbatch_continues_an_interrupted_part(tmp_path):
    """A task stopped early (as Slurm's --signal=B:INT before a time limit does; here
    --time-limit 0 stops after the first pass) leaves an incomplete part, which merge
    refuses; running the task again resumes the part, and the image equals one render.
    Bidirectional path tracing splats, so its passes are of 2^20 samples: about 5 of the
    8 spp of this 512x384 scene."""
    outdir = tmp_path / "parts"
    flags = ("--spp", "8", "--seed", "5")
    env = dict(HERON_SHARDS=1, SLURM_CPUS_ON_NODE=2)
    proc = _render_shard(outdir, 0, 1, SLURM_SCENE, (*flags, "--time-limit", "0"), **env)
    assert proc.returncode == 0, proc.stderr
    held = re.search(r"time limit reached: the film holds (\d+) of 8 spp", proc.stderr)
    assert held and 0 < int(held.group(1)) < 8, proc.stderr

    out = tmp_path / "merged.exr"
    proc = _run(["bash", SLURM_DIR / "merge.sbatch", outdir, 1, out], env=_script_env())
    assert proc.returncode == 1 and "is incomplete" in proc.stderr, proc.stderr
    assert not out.exists()

    proc = _render_shard(outdir, 0, 1, SLURM_SCENE, flags, **env)
    assert proc.returncode == 0, proc.stderr
    assert f"continuing {outdir}/part-0.heronfilm" in proc.stdout, proc.stdout
    assert f"resumed from {held.group(1)} spp" in proc.stderr, proc.stderr
    proc = _run(["bash", SLURM_DIR / "merge.sbatch", outdir, 1, out], env=_script_env())
    assert proc.returncode == 0, proc.stderr
    ref = _render_reference(SLURM_SCENE, flags, tmp_path / "ref.exr")
    assert out.read_bytes() == ref.read_bytes()
    assert out.with_suffix(".png").read_bytes() == ref.with_suffix(".png").read_bytes()

    # Another render's part in the same place is refused, not overwritten.
    before = (outdir / "part-0.heronfilm").read_bytes()
    proc = _render_shard(outdir, 0, 1, SLURM_SCENE, ("--spp", "8", "--seed", "6"), **env)
    assert proc.returncode == 1 and "--resume" in proc.stderr, proc.stderr
    assert (outdir / "part-0.heronfilm").read_bytes() == before


def test_render_array_sbatch_refuses_a_task_beyond_n(tmp_path):
    proc = _render_shard(tmp_path, 4, 4, HERON_SHARDS=4)
    assert proc.returncode == 2
    assert proc.stderr.strip() == (
        "render-array.sbatch: array task 4 is not a shard of 4 (shards are 0..3); "
        "submit --array=0-3 or set HERON_SHARDS"), proc.stderr
    proc = _render_shard(tmp_path, 0, 0, HERON_SHARDS="x")
    assert proc.returncode == 2
    assert "HERON_SHARDS must be a positive integer, not 'x'" in proc.stderr
    assert not list(tmp_path.iterdir())


# --- the Kubernetes recipe (not run on Kubernetes) ----------------------------------------

def _load_yaml_documents(path: pathlib.Path) -> list:
    """The YAML documents of PATH, parsed by PyYAML: the venv's if it has one, else the
    system Python's (Debian's python3-yaml, installed by scripts/setup.sh --deps), whose
    result comes back as JSON."""
    try:
        import yaml  # noqa: PLC0415
    except ImportError:
        yaml = None
    if yaml is not None:
        with open(path) as f:
            return [d for d in yaml.safe_load_all(f) if d is not None]
    code = ("import json, sys, yaml\n"
            "docs = [d for d in yaml.safe_load_all(open(sys.argv[1])) if d is not None]\n"
            "print(json.dumps(docs))")
    proc = _run(["/usr/bin/python3", "-c", code, path], timeout=60)
    assert proc.returncode == 0, (
        f"could not parse {path} with the system Python's PyYAML (Debian: python3-yaml, "
        f"installed by scripts/setup.sh --deps):\n{proc.stderr}")
    return json.loads(proc.stdout)


def _container_env(container: dict) -> dict:
    return {e["name"]: e.get("value") for e in container.get("env", [])}


def test_k8s_manifest_renders_and_merges(tmp_path):
    """deploy/k8s/render-job.yaml: a PVC, an Indexed Job of N completions whose pods
    render shard $JOB_COMPLETION_INDEX/N onto the volume, and a merge Job that waits for
    the N parts and merges them. The structure is checked, then the containers' shell
    commands run here for every index (the volume a temporary folder, a small scene and
    few samples instead of the manifest's), and the merged image must equal one render."""
    docs = _load_yaml_documents(K8S_MANIFEST)
    kinds = [d["kind"] for d in docs]
    assert kinds == ["PersistentVolumeClaim", "Job", "Job"], kinds
    pvc, render_job, merge_job = docs
    claim = pvc["metadata"]["name"]

    spec = render_job["spec"]
    assert spec["completionMode"] == "Indexed"
    n = spec["completions"]
    assert isinstance(n, int) and n >= 2 and 1 <= spec["parallelism"] <= n
    pod = spec["template"]["spec"]
    assert pod["restartPolicy"] in ("Never", "OnFailure")
    (render,) = pod["containers"]
    render_env = _container_env(render)
    assert render_env["HERON_SHARDS"] == str(n), "HERON_SHARDS must equal completions"

    merge_pod = merge_job["spec"]["template"]["spec"]
    assert merge_job["spec"].get("completionMode", "NonIndexed") == "NonIndexed"
    (wait,) = merge_pod["initContainers"]
    (merge,) = merge_pod["containers"]
    # The settings the three containers share are the same in each.
    for c in (wait, merge):
        env = _container_env(c)
        assert env["HERON_SHARDS"] == str(n), c["name"]
        for key in ("HERON_RUN", "HERON_WORK", "HERON_SCENE"):
            if key in env:
                assert env[key] == render_env[key], (c["name"], key)
    render_threads = next(e for e in render["env"] if e["name"] == "HERON_THREADS")
    assert render_threads["valueFrom"]["resourceFieldRef"]["resource"] == "limits.cpu"

    # Every container mounts the claim at the path its HERON_WORK names.
    for p, containers in ((pod, [render]), (merge_pod, [wait, merge])):
        volumes = {v["name"]: v for v in p["volumes"]}
        for c in containers:
            (mount,) = c["volumeMounts"]
            assert volumes[mount["name"]]["persistentVolumeClaim"]["claimName"] == claim
            assert _container_env(c)["HERON_WORK"] == mount["mountPath"], c["name"]
            assert c["image"] == render["image"]

    # Run the containers' commands here: the image's /opt/heron is the repository and
    # heron is on PATH (as in deploy/k8s/Dockerfile); the volume is a temporary folder.
    bindir = tmp_path / "bin"
    bindir.mkdir()
    (bindir / "heron").symlink_to(require_heron_bin())
    work = tmp_path / "volume"
    work.mkdir()

    def run(container, **extra):
        env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}
        env.update({k: v for k, v in _container_env(container).items() if v is not None})
        if "HERON_SCENE" in env:
            # The image's scene exists in the repository; the run takes a smaller one.
            assert env["HERON_SCENE"].startswith("/opt/heron/"), env["HERON_SCENE"]
            assert (REPO / env["HERON_SCENE"].removeprefix("/opt/heron/")).is_file()
            env["HERON_SCENE"] = str(SMALL_SCENE)
        env.update(HERON_WORK=str(work), HERON_FLAGS=shlex.join(SMALL_FLAGS),
                   PATH=f"{bindir}:{env['PATH']}", HERON_THREADS="1")
        env.update({k: str(v) for k, v in extra.items()})
        cmd = [*container["command"], *container.get("args", [])]
        return _run(cmd, env=env)

    assert SMALL_FLAGS != tuple(shlex.split(render_env["HERON_FLAGS"]))
    for k in range(n):
        proc = run(render, JOB_COMPLETION_INDEX=k)
        assert proc.returncode == 0, f"index {k}: {proc.stderr}"
    parts = sorted(p.name for p in work.rglob("*.heronfilm"))
    assert parts == sorted(f"part-{k}.heronfilm" for k in range(n)), parts
    proc = run(wait)
    assert proc.returncode == 0, proc.stderr
    proc = run(merge)
    assert proc.returncode == 0, proc.stderr
    (merged,) = work.rglob("*.exr")
    assert merged == work / render_env["HERON_RUN"] / f"{SMALL_SCENE.stem}.exr"
    ref = _render_reference(SMALL_SCENE, SMALL_FLAGS, tmp_path / "ref.exr")
    assert merged.read_bytes() == ref.read_bytes()

    # The wait gives up (non-zero, naming the part) when a part never comes.
    next(work.rglob("part-1.heronfilm")).unlink()
    proc = run(wait, HERON_WAIT_SECONDS=0)
    assert proc.returncode != 0 and "part-1.heronfilm" in proc.stderr, proc.stderr
