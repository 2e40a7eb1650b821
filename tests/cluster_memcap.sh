#!/usr/bin/env bash
# tests/cluster_memcap.sh — proof at size (issue 37 goal 7, docs/cluster.md): a 1024x768x512 uint16 volume
# (768 MiB, raw) rendered sort-last by 4 ranks, each rank in its own memory cgroup capped at 640 MiB — below
# the volume's own size, and far below what one process needs for it (measured 1.6 GiB charged: the volume
# on the host and on the device), which the same cap kills — and the 4-rank image equals one process's
# within 2e-5 (EXR). The cgroup charges the memory a process touches first (its anonymous memory; shared
# libraries and the file's page cache, read first by the uncapped run, are charged elsewhere). Each rank reads only its part (loadVolumeRegion). Needs a writable cgroup v1
# memory controller (/sys/fs/cgroup/memory), as root.
# Usage: cluster_memcap.sh CLVR MPIEXEC OIIOTOOL WORK
set -euo pipefail
clvr=$1 mpiexec=$2 oiiotool=$3 work=$4
cap=$((640 * 1024 * 1024))
memcg=/sys/fs/cgroup/memory
rm -rf "$work"
mkdir -p "$work/mpi"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_orte_tmpdir_base="$work/mpi"
if ! mkdir "$memcg/clvr-memcap-probe-$$" 2>/dev/null; then
    echo "cluster_memcap: no writable memory cgroup at $memcg (the test needs one, as root)" >&2
    exit 1
fi
rmdir "$memcg/clvr-memcap-probe-$$"

# The volume: a smooth blob, x fastest, written with numpy (Debian's /usr/bin/python3).
/usr/bin/python3 - "$work/blob.raw" <<'PY'
import sys
import numpy as np
x = np.linspace(-1, 1, 1024, dtype=np.float32)[None, :]
y = np.linspace(-1, 1, 768, dtype=np.float32)[:, None]
with open(sys.argv[1], "wb") as f:
    for z in np.linspace(-1, 1, 512, dtype=np.float32):  # one z plane at a time: 1.5 MiB of uint16 each
        plane = 60000 * np.exp(-3 * (x * x + y * y + z * z)) * (1 + 0.2 * np.sin(9 * x) * np.cos(7 * y))
        f.write(np.clip(plane, 0, 65535).astype("<u2").tobytes())
PY
cat > "$work/blob.json" <<'JSON'
{"technique": "slice3d",
 "volume": {"file": "blob.raw", "dims": [1024, 768, 512], "type": "uint16", "endian": "little"},
 "image": {"width": 96, "height": 96, "background": [0.1, 0.1, 0.15]},
 "transfer_function": {"points": [[0, 0,0,0, 0], [20000, 0.2,0.4,1, 0.002], [45000, 1,0.8,0.3, 0.02], [65535, 1,1,1, 0.05]]}}
JSON

# Runs "$@" in a new memory cgroup capped at $cap (the cgroups are removed at the end).
cat > "$work/capped.sh" <<EOF2
#!/usr/bin/env bash
cg=$memcg/clvr-memcap-\$\$
mkdir "\$cg" && echo $cap > "\$cg/memory.limit_in_bytes" && echo \$\$ > "\$cg/cgroup.procs" && exec "\$@"
EOF2
chmod +x "$work/capped.sh"
cleanup() {
    for cg in "$memcg"/clvr-memcap-*; do
        [ -d "$cg" ] && rmdir "$cg" 2>/dev/null || true
    done
    rm -f "$work/blob.raw"  # 768 MiB
}
trap cleanup EXIT

# One process, uncapped: the reference image (and the kernels compiled into PoCL's cache).
"$clvr" render "$work/blob.json" -o "$work/one.exr" --single-frame
# The cap is below the whole volume's need: one process under it is killed (or fails), and writes nothing.
if "$work/capped.sh" "$clvr" render "$work/blob.json" -o "$work/one-capped.exr" --single-frame 2>/dev/null; then
    echo "cluster_memcap: one process rendered the whole volume under the $((cap >> 20)) MiB cap: the cap proves nothing" >&2
    exit 1
fi
test ! -e "$work/one-capped.exr"
# Four ranks, each under the cap, each reading its part.
"$mpiexec" --oversubscribe --bind-to none -np 4 "$work/capped.sh" "$clvr" render "$work/blob.json" \
    -o "$work/four.exr" --single-frame --stats "$work/four.json"
"$oiiotool" "$work/one.exr" "$work/four.exr" --fail 2e-5 --diff
/usr/bin/python3 - "$work/four.json" "$cap" <<'PY'
import json, sys
stats, cap = json.load(open(sys.argv[1])), int(sys.argv[2])
peaks = stats["host_peak_bytes_per_rank"]
# Resident peaks include the shared libraries' pages, which the cgroups do not charge (above): reported only.
print("resident peak per rank (MiB):", [round(p / 2**20) for p in peaks], "| rank 0 read", stats["rank0_part"])
assert len(peaks) == 4, peaks
assert stats["rank0_part"].endswith("points read"), stats["rank0_part"]
PY
echo "cluster_memcap: 4 ranks under $((cap >> 20)) MiB each rendered the image of one uncapped process"
