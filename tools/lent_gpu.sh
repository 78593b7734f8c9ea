#!/usr/bin/env bash
# Issue 11 item 7: the benchmarks and the GPU test suite on a lent GPU (the `device` tool of the
# developers' workplace; see BENCHMARKS.md "A real GPU"). Run there from the repository root as
#     tools/lent_gpu.sh STEP...      (STEP: setup info tests resident cli maps bench ...)
# with two carried folders, both ignored by git (.git/info/exclude):
#   .gl/   the Vulkan loader's Debian packages (the machine has the NVIDIA driver, not the loader);
#   .dev/  bins.tar.xz: x86-64 release binaries built here (luxeval, examples/resident,
#          examples/resident_sampling and the
#          GPU test binaries, `cargo test --release --no-run`), stripped; optionally
#          luxeval_old, an earlier luxeval to compare with in the same run.
# Making .dev, here (release builds; --tests builds every test binary, --lib the unit tests):
#     cargo test --release --ignore-rust-version --no-run --lib --tests 2>&1 | tee /tmp/b.log
#     cargo build --release --ignore-rust-version --features testkit --bins --example resident \
#         --example resident_sampling
#     mkdir -p /tmp/stage && cp target/release/luxeval target/release/examples/resident \
#         target/release/examples/resident_sampling /tmp/stage
#     for f in $(grep Executable /tmp/b.log | awk '{print $NF}' | tr -d '()'); do
#         cp "$f" /tmp/stage/t_$(basename "$f" | sed 's/-[0-9a-f]*$//'); done
#     strip /tmp/stage/*; (cd /tmp/stage && tar cf - * | xz -9) > .dev/bins.tar.xz
# and .gl with the README of the device tool (apt-get download libvulkan1 ... for amd64).
# The test binaries were built in /work/main, so CARGO_MANIFEST_DIR and CARGO_BIN_EXE_luxeval
# point there: /work/main is made a link to this copy. Every log goes to $OUT.
set -u
OUT=${OUT:-/tmp/lent-out}
mkdir -p "$OUT"
ROOT=$PWD
TIMEFORMAT='%R s wall, %U s user, %S s sys'

setup() {
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
    icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    [ -f "$icd" ] && echo "export VK_DRIVER_FILES=$icd" >> /tmp/lent-env
    egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    [ -f "$egl" ] && echo "export __EGL_VENDOR_LIBRARY_FILENAMES=$egl" >> /tmp/lent-env
    if [ "$ROOT" != /work/main ]; then mkdir -p /work && rm -rf /work/main && ln -s "$ROOT" /work/main; fi
    mkdir -p target/release target/tmp /tmp/bins
    tar xJf .dev/bins.tar.xz -C /tmp/bins
    cp /tmp/bins/luxeval target/release/luxeval
    # One receiver for the irradiance commands' start-up (the luxtest floor's centre, facing up).
    python3 -c 'import numpy as np; np.save("/tmp/p1.npy", np.array([[0, 0, 0]], np.float32)); np.save("/tmp/n1.npy", np.array([[0, 1, 0]], np.float32))'
    { nvidia-smi; nproc; free -g; cat /tmp/lent-env; } > "$OUT/machine.txt" 2>&1
}

info() {
    target/release/luxeval info --json > "$OUT/info.json" 2>&1
    target/release/luxeval info
}

tests() {
    # CI=true: a GPU test fails, rather than skips, when no adapter is found.
    # TEST_FILTER: the test-name filters given to every binary (none: all of its tests).
    for t in /tmp/bins/t_*; do
        case "${t##*/t_}" in ${SKIP_TESTS:-none}) echo "=== ${t##*/t_}: skipped this run"; continue ;; esac
        echo "=== ${t##*/t_}"
        ( time CI=true timeout ${TEST_TIMEOUT:-240} "$t" --test-threads 16 ${TEST_FILTER:-} 2>&1 | tail -n 40 ) 2>&1
    done > "$OUT/tests.log" 2>&1
    grep -E '^(===|test result|real|.*FAILED|.*panicked)' "$OUT/tests.log" | head -n 80
}

resident() {
    # GPU-resident emission against the bandwidth bound (issue 24 item 7): packed (12-byte) and
    # vec4 (16-byte) rows, 1 to 4 rows an invocation (the last argument), 10 passes a submit;
    # each prints the wall time per pass and the device's own (timestamp queries).
    {
        for shape in "1 16000000 20 sum 10" "1 16000000 20 per-light 10" \
            "8 4000000 20 per-light 10" "8 16000000 10 sum 4" "1 64000000 10 sum 4"; do
            for layout in packed vec4; do
                for r in 1 2 4; do
                    echo "=== resident $shape $layout $r"
                    timeout 60 /tmp/bins/resident $shape $layout $r 2>&1
                done
            done
        done
        for args in "8 4000000 20 sum 10" "64 4000000 10 sum 4"; do
            echo "=== resident $args packed 1"
            timeout 60 /tmp/bins/resident $args packed 1 2>&1
        done
        # Light sampling (issue 23: 8 mixed lights × 4M samples, ≥ 1e9 samples/s GPU-resident).
        for args in "8 65536 64 20 bound 10" "8 65536 64 20 power 10" "64 65536 64 10 bound 4"; do
            echo "=== resident_sampling $args"
            timeout 60 /tmp/bins/resident_sampling $args 2>&1
        done
    } > "$OUT/resident.log" 2>&1
    grep -E '^(===|emission|sampling)' "$OUT/resident.log"
}

maps() {
    # "The jobs people run" (BENCHMARKS.md, issue 24): every luxtest floor, 128² and 1024², on
    # the GPU and the CPU reference (16 cores), 1e-4 and 1e-2; luxeval_old (when carried) is
    # the earlier binary, run in turn with the new one. Whole process, pipeline cache warm
    # (a first run per scene fills it and is not timed). Each run is stopped after MAP_TIMEOUT
    # seconds (20): the H200 run of 2026-11-26 spent most of its call on old binaries' host
    # integrals stopped at 45 s, and never reached its last steps. Run `ceiling` first.
    floor="--origin -5,0,5 --u 10,0,0 --v 0,0,-10"
    export LUXEVAL_CACHE_DIR=/tmp/lent-cache
    bins="luxeval"
    [ -x /tmp/bins/luxeval_old ] && bins="luxeval_old luxeval"
    {
        for sf in rect:31 sphere:31 disk:31 cylinder:31 distant:12 iesTest:15 dome:1 visibleRect:1; do
            scene=${sf%%:*}; frame=${sf##*:}
            f=tests/data/luxtest/usd/$scene.usda
            for b in $bins; do
                timeout 60 /tmp/bins/$b falloff $f --time $frame $floor --res 16,16 -o /tmp/w.exr --device gpu >/dev/null 2>&1
            done
            # GPU: old and new at 1e-4 (the device's f32 rule does not take a tolerance);
            # CPU (new only): 128² at 1e-4, 1024² at 1e-4 and 1e-2.
            for run in "gpu 128 1e-4 $bins" "gpu 1024 1e-4 $bins" "cpu 128 1e-4 luxeval" \
                "cpu 1024 1e-4 luxeval" "cpu 1024 1e-2 luxeval"; do
                set -- $run; dev=$1; res=$2; tol=$3; shift 3
                for b in "$@"; do
                    echo "--- $b $scene $res $dev $tol"
                    ( time timeout ${MAP_TIMEOUT:-20} /tmp/bins/$b falloff $f --time $frame $floor --res $res,$res -o /tmp/m_${b}_${dev}.exr --device $dev --tolerance $tol >/dev/null ) 2>&1 | grep -E 'wall|rror'
                done
            done
        done
    } > "$OUT/maps.log" 2>&1
    cat "$OUT/maps.log"
}

cli() {
    L=target/release/luxeval
    floor="--origin -5,0,5 --u 10,0,0 --v 0,0,-10"
    export LUXEVAL_CACHE_DIR=/tmp/lent-cache
    rm -rf /tmp/lent-cache
    {
        for pass in "first (no cache file)" "second (cache file)"; do
            echo "=== $pass"
            echo "--- quick start"; time $L emission assets/studio.usda --dirs assets/dirs.npy -o /tmp/e.npy
            echo "--- info"; time $L info > /dev/null
            echo "--- irradiance rect one point"; time $L irradiance tests/data/luxtest/usd/rect.usda --time 31 --points /tmp/p1.npy --normals /tmp/n1.npy -o /tmp/i.npy
            echo "--- irradiance studio one point"; time $L irradiance assets/studio.usda --points /tmp/p1.npy --normals /tmp/n1.npy -o /tmp/i.npy
        done
        ls -la /tmp/lent-cache
        for scene in rect sphere; do
            f=tests/data/luxtest/usd/$scene.usda
            [ -f "$f" ] || { echo "no $f"; continue; }
            for dev in gpu cpu; do
                echo "--- falloff 128 $scene $dev"
                time $L falloff "$f" --time 31 $floor --res 128,128 -o /tmp/m_$dev.exr --device $dev
            done
            echo "--- falloff 128 $scene cpu 1e-9"
            time $L falloff "$f" --time 31 $floor --res 128,128 -o /tmp/m_ref.exr --device cpu --tolerance 1e-9
        done
        for dev in gpu cpu; do
            echo "--- falloff 1024 rect $dev"
            time $L falloff tests/data/luxtest/usd/rect.usda --time 31 $floor --res 1024,1024 -o /tmp/big_$dev.exr --device $dev
        done
        echo "--- check"; time $L check tests/data/luxtest/usd/rect.usda --time 31
    } > "$OUT/cli.log" 2>&1
    grep -E '^(===|---|[0-9.]+ s wall)' "$OUT/cli.log"
}

startup() {
    # The irradiance command's start-up on a machine whose caches start empty: with neither the
    # driver's shader cache nor luxeval's pipeline cache, with luxeval's alone, with the
    # driver's alone (NVIDIA's is on by default; __GL_SHADER_DISK_CACHE=0 turns it off).
    L=target/release/luxeval
    cmd="irradiance tests/data/luxtest/usd/rect.usda --time 31 --points /tmp/p1.npy --normals /tmp/n1.npy -o /tmp/i.npy"
    rm -rf /tmp/c1 ~/.cache/nvidia ~/.nv
    {
        for i in 1 2; do echo "--- no cache $i"; time env __GL_SHADER_DISK_CACHE=0 LUXEVAL_CACHE_DIR= $L $cmd; done
        for i in 1 2; do echo "--- luxeval cache only $i"; time env __GL_SHADER_DISK_CACHE=0 LUXEVAL_CACHE_DIR=/tmp/c1 $L $cmd; done
        ls -la /tmp/c1
        for i in 1 2; do echo "--- driver cache only $i"; time env LUXEVAL_CACHE_DIR= $L $cmd; done
        echo "--- quick start, luxeval cache"; time env LUXEVAL_CACHE_DIR=/tmp/c1 $L emission assets/studio.usda --dirs assets/dirs.npy -o /tmp/e.npy
        echo "--- falloff 128 rect, luxeval cache"; time env LUXEVAL_CACHE_DIR=/tmp/c1 $L falloff tests/data/luxtest/usd/rect.usda --time 31 --origin -5,0,5 --u 10,0,0 --v 0,0,-10 --res 128,128 -o /tmp/m.exr
        echo "--- falloff 128 sphere, luxeval cache"; time env LUXEVAL_CACHE_DIR=/tmp/c1 $L falloff tests/data/luxtest/usd/sphere.usda --time 31 --origin -5,0,5 --u 10,0,0 --v 0,0,-10 --res 128,128 -o /tmp/m.exr
    } > "$OUT/startup.log" 2>&1
    grep -E '^(---|[0-9.]+ s wall)' "$OUT/startup.log"
}

versus() {
    # The host path before and after, alternating, in one run (luxeval_old: the earlier binary).
    [ -x /tmp/bins/luxeval_old ] || { echo "no luxeval_old"; return; }
    for i in 1 2; do
        for b in luxeval_old luxeval; do
            echo "=== $b $i"
            /tmp/bins/$b bench --samples 4000000 --cpu-samples 4000000 --lights 8 --repeat 5 \
                --no-dome --no-startup --json 2>/dev/null | python3 -c 'import json,sys; b=json.load(sys.stdin); [print(q["query"], q["device"], q["samples"], "%.4f s" % q["median_seconds"], "%.3e/s" % q["evals_per_second"]) for q in b["queries"]]; print("ratios", b["ratios"])'
        done
    done > "$OUT/versus.log" 2>&1
    cat "$OUT/versus.log"
}

ceiling() {
    # The card's two bounds, measured here (not datasheet figures): device memory bandwidth (a
    # 2 GiB device-to-device copy, bytes read plus written) and PCIe each way (pinned host
    # memory), through PyTorch's CUDA, which the machine's image holds.
    python3 - <<'PY' 2>&1 | tee "$OUT/ceiling.log"
import torch
def timed(f, reps=20):
    for _ in range(3): f()
    torch.cuda.synchronize()
    s, e = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
    s.record()
    for _ in range(reps): f()
    e.record(); torch.cuda.synchronize()
    return s.elapsed_time(e) / reps / 1e3
n = 1 << 29  # floats: 2 GiB
x = torch.rand(n, device="cuda"); y = torch.empty_like(x)
t = timed(lambda: y.copy_(x))
print(f"device-to-device copy: {2 * 4 * n / t / 1e9:.0f} GB/s (read + write), {t * 1e3:.3f} ms")
h = torch.rand(n // 4).pin_memory(); d = torch.empty(n // 4, device="cuda")
t = timed(lambda: d.copy_(h, non_blocking=True))
print(f"host-to-device (pinned): {4 * (n // 4) / t / 1e9:.1f} GB/s")
t = timed(lambda: h.copy_(d, non_blocking=True))
print(f"device-to-host (pinned): {4 * (n // 4) / t / 1e9:.1f} GB/s")
PY
}

bench() {
    ( time target/release/luxeval bench --samples 4000000 --cpu-samples 4000000 --lights 8 --repeat 3 \
        --sweep --sweep-samples 1000,10000,100000,1000000,10000000 --sweep-lights 1,8,64 \
        --json > "$OUT/bench.json" ) 2> "$OUT/bench.log"
    tail -n 5 "$OUT/bench.log"
    python3 -c 'import json,sys; json.dump(json.load(open(sys.argv[1])), sys.stdout, indent=1)' \
        "$OUT/bench.json" | head -c 3000
}

for step in "$@"; do
    [ -f /tmp/lent-env ] && . /tmp/lent-env
    echo "##### $step"
    time "$step"
done
