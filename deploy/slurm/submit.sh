#!/usr/bin/env bash
# Submits a sharded heron render to Slurm: a job array of N tasks (render-array.sbatch,
# task K renders shard K/N into OUTDIR/part-K.heronfilm) and a merge job that starts when
# all of them succeeded (merge.sbatch, --dependency=afterok) and writes OUTDIR/SCENE.exr
# (SCENE: the scene file's name without .toml) and its PNG preview.
#
#   deploy/slurm/submit.sh SCENE N OUTDIR [heron render flags...]
#
#   deploy/slurm/submit.sh scenes/rainbow-descartes.toml 16 /shared/runs/bow --spp 65536 --seed 3
#
# Prints, one per line (for eval or grep):
#   ARRAY_JOB=<id>     the render array; its tasks log to OUTDIR/logs/render-<id>_<K>.out
#   MERGE_JOB=<id>     the merge; it logs to OUTDIR/logs/merge-<id>.out
#   OUTPUT=<path>      the image the merge writes
# Follow them with `squeue -j ARRAY,MERGE` or `scontrol show job ID`. If a task fails the
# merge is cancelled (--kill-on-invalid-dep); resubmit that task alone with
#   sbatch --array=K --export=ALL,HERON_SHARDS=N,HERON_BIN=... render-array.sbatch SCENE OUTDIR FLAGS
# and the merge with merge.sbatch (see the top of each file); a task stopped at its time
# limit continues from the samples it wrote. Use a new OUTDIR for each render: a task
# refuses an existing part of another render.
#
# Environment:
#   HERON_BIN          heron binary (default: `heron` on this PATH), resolved to an
#                      absolute path; it, SCENE (with its meshes and spectra) and OUTDIR
#                      must be at the same paths on the compute nodes (a shared file system)
#   HERON_SBATCH_OPTS  extra sbatch options for both jobs, split on spaces, e.g.
#                      "--partition=long --time=2:00:00 --cpus-per-task=8"
#   HERON_MERGE_FLAGS  extra heron merge flags, e.g. "--no-png"
#   SLURM_CONF         as for any Slurm command (tests/slurm/cluster.sh sets it)
set -euo pipefail

die() {
  echo "submit.sh: $*" >&2
  exit 2
}

[ $# -ge 3 ] || die "usage: submit.sh SCENE N OUTDIR [heron render flags...]"
scene=$1
n=$2
outdir=$3
shift 3

case "$n" in
  '' | *[!0-9]*) die "N (shards) must be a positive integer, not '$n'" ;;
esac
[ "$n" -ge 1 ] || die "N (shards) must be a positive integer, not '$n'"
[ -f "$scene" ] || die "scene '$scene' not found"
command -v sbatch >/dev/null 2>&1 || die "sbatch not found: is this a Slurm submit host?"

heron=${HERON_BIN:-heron}
heron_path=$(command -v "$heron" 2>/dev/null) || die "heron binary '$heron' not found (set HERON_BIN)"
case "$heron_path" in
  /*) ;;
  *) heron_path=$(cd "$(dirname "$heron_path")" && pwd -P)/$(basename "$heron_path") ;;
esac

here=$(cd "$(dirname "$0")" && pwd -P)
scene_abs=$(cd "$(dirname "$scene")" && pwd -P)/$(basename "$scene")
mkdir -p "$outdir/logs"
outdir_abs=$(cd "$outdir" && pwd -P)
output="$outdir_abs/$(basename "$scene" .toml).exr"

# shellcheck disable=SC2206 # the options are meant to be split on spaces
extra_sbatch=(${HERON_SBATCH_OPTS:-})
# shellcheck disable=SC2206
merge_flags=(${HERON_MERGE_FLAGS:-})

# --parsable prints "jobid" or "jobid;cluster".
array_job=$(sbatch --parsable --array="0-$((n - 1))" \
  --export="ALL,HERON_BIN=$heron_path,HERON_SHARDS=$n" \
  --output="$outdir_abs/logs/render-%A_%a.out" \
  "${extra_sbatch[@]}" \
  "$here/render-array.sbatch" "$scene_abs" "$outdir_abs" "$@")
array_job=${array_job%%;*}

if ! merge_job=$(sbatch --parsable --dependency="afterok:$array_job" --kill-on-invalid-dep=yes \
  --export="ALL,HERON_BIN=$heron_path" \
  --output="$outdir_abs/logs/merge-%j.out" \
  "${extra_sbatch[@]}" \
  "$here/merge.sbatch" "$outdir_abs" "$n" "$output" "${merge_flags[@]}"); then
  # Without its merge the array would render for nothing.
  scancel "$array_job" || true
  die "the merge job was not accepted (sbatch's message above); cancelled the render array $array_job"
fi
merge_job=${merge_job%%;*}

echo "ARRAY_JOB=$array_job"
echo "MERGE_JOB=$merge_job"
echo "OUTPUT=$output"
