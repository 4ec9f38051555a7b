"""make report's run time on the Cortex-M3: each precision-knob configuration's firmware under QEMU.

For a configuration (its flags from mk/report.mk) the firmware is built once per view's scene with
the flags (make firmware KNOB_DEFS=... FULL=1 FW_MODES=columns STREAM=raw, 16 MB of RAM and a fixed
8 MB work area), its objects in OUT/m3/CONFIG/obj, each scene's part in OUT/m3/SCENE (compiled into C
once and shared by every configuration). It runs mps2-an385 with build/insn_count.so at each view,
the world alone (--no-objects, as the x86-64 figures) in mode columns (the board's mode), and a
view's figure is the median of frames 2 and 3 (tools/qemu_plugin/bench_m3.py counts the same way).
The Cortex-M3 has no divide of 64-bit numbers and a 32-bit one costs cycles there: the reciprocal
knobs are for it.

Figures are cached by the flags, the digest of the sources the firmware is built from, and the
view, so a re-run builds and runs only what changed."""
import hashlib
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
sys.path.insert(0, str(ROOT / "tools" / "qemu_plugin"))
import bench_m3  # noqa: E402

MODE = "columns"
FRAMES = 3  # the first is left out
WORK_BYTES = 8 * 1024 * 1024
# what the firmware is built from
SOURCES = ("firmware", "hal", "mk/mps2.mk", "mk/modes.mk", "hal/mps2/mps2.ld")


def sources_digest():
    h = hashlib.sha1()
    files = []
    for s in SOURCES:
        p = ROOT / s
        files += sorted(q for q in p.rglob("*") if q.is_file() and q.suffix in (".c", ".h", ".ld", ".mk")) \
            if p.is_dir() else [p]
    for f in files:
        h.update(str(f.relative_to(ROOT)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def _safe(name):
    return "".join(c if c.isalnum() or c in "._-" else "_" for c in name)


def build(config, flags, scene, out, jobs):
    """The firmware of configuration config for scene: its ELF."""
    scene_dir = out / _safe(scene)
    proc = subprocess.run(
        ["make", "-s", "--no-print-directory", f"-j{jobs}", "firmware", f"SCENE={scene}", f"ARM_OUT={scene_dir}",
         f"ARM_OBJ={out / _safe(config) / 'obj'}", f"KNOB_DEFS={flags}", "FULL=1", f"FW_MODES={MODE}",
         "STREAM=raw", "RAM_BYTES=16777216", f"WORK_BYTES={WORK_BYTES}"],
        cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"make firmware for {config} ({flags or 'no flags'}), {scene}:\n{proc.stdout}{proc.stderr}")
    return scene_dir / "firmware.elf"


def count(elf, view):
    """Median instructions per frame of the view after the first frame."""
    args = ["--at", view["at"], "--angle", view["angle"], "--mode", MODE, "--frames", str(FRAMES), "--no-stream",
            "--no-tick", "--no-objects"] + (["--look", str(view["look"])] if view.get("look") else [])
    counts, _ = bench_m3.count(elf, args, elf.parent / "insns.txt")
    return int(statistics.median(counts[1:]))


def measure(configs, views, out, cache, log, jobs=2):
    """{config: [instructions per frame of each view]} for configs {name: flags} over views (each
    with scene, at, angle), the Cortex-M3 build of each configuration."""
    subprocess.run(["make", "-s", "--no-print-directory", "insn-plugin"], cwd=ROOT, check=True, capture_output=True)
    src = sources_digest()
    scenes = list(dict.fromkeys(v["scene"] for v in views))
    result, t0 = {}, time.time()
    for k, (config, flags) in enumerate(configs.items(), 1):
        keys = [f"m3:{src}:{flags}:{v['scene']}:{v['at']}:{v['angle']}:{v.get('look', 0)}" for v in views]
        figures = [cache.get(key) for key in keys]
        for scene in scenes:
            todo = [i for i, v in enumerate(views) if v["scene"] == scene and figures[i] is None]
            if not todo:
                continue
            elf = build(config, flags, scene, out, jobs)
            for i in todo:  # one QEMU at a time: the scene's ELF is rebuilt for the next configuration
                figures[i] = count(elf, views[i])
                cache.put(keys[i], figures[i])
        cache.save()
        result[config] = figures
        left = (time.time() - t0) / k * (len(configs) - k)
        log(f"Cortex-M3: {k}/{len(configs)} configurations, {config}: median "
            f"{statistics.median(figures):,.0f} instructions per frame"
            + (f", about {left / 60:.0f} min left" if k < len(configs) else ""))
    return result
