#!/usr/bin/python3
"""Cost per step against mesh size: the compressed sleeve of the paper's timing scene at several sizes.

Usage:
  scaling.py run  --bin CLOTHSIM --csv OUT.csv [--label NAME] [--sizes 62x41,124x81,...]
                  [--end 0.2] [--repeats 3] [--contact] [--scene SCENE.json] [--set KEY=VALUE ...]
  scaling.py plot OUT.png A.csv [B.csv ...]     (one curve per label)
  scaling.py table A.csv [B.csv ...]            (Markdown table on stdout)

`run` runs scenes/sleeve_compress_2542.json (dt = 0.01 s; --scene: another version of it, e.g. the
file as it was at the commit an older binary was built from) with mesh.segments x mesh.rings
replaced, to --end (default 0.2 s: 20 steps), without rendering or OBJ output and, unless
--contact, without self-collision, each size --repeats times in separate processes, the sizes
interleaved (size 1, 2, ..., then again), and appends one row per run to the CSV:

  label, segments, rings, vertices, steps, repeat, ms_per_step (rotate + assemble + solve from
  summary.json, the issue's measure), rotate_ms, assemble_ms, solve_ms, factor_ms (per step),
  factorizations, iterations (per step), contact_ms (per step), wall_seconds (the whole process:
  set-up included), peak_rss_MiB (the process's maximum resident set, from wait4), load_1min
  (the machine's 1-minute load average when the run started).

`table` prints, per label and size, the medians over the repeats: ms per step, µs per vertex per
step, the phase split, iterations and factorisations per step, peak memory and bytes per vertex.
`plot` draws µs per vertex per step against vertices (log x), one curve per label.
"""
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

from bench_cli import die, dispatch

FIELDS = ["label", "segments", "rings", "vertices", "steps", "repeat", "ms_per_step", "rotate_ms", "assemble_ms",
          "solve_ms", "factor_ms", "factorizations", "iterations", "contact_ms", "wall_seconds", "peak_rss_MiB",
          "load_1min"]
DEFAULT_SIZES = "62x41,124x81,248x161,396x253"
SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "sleeve_compress_2542.json")




def parse_sizes(text):
    sizes = []
    for item in text.split(","):
        try:
            s, r = item.lower().split("x")
            sizes.append((int(s), int(r)))
        except ValueError:
            die("--sizes: expected SEGMENTSxRINGS[,...], got '%s'" % item)
    return sizes


def one_run(binary, scene, segments, rings, end, contact, extra_sets):
    with tempfile.TemporaryDirectory(prefix="clothsim_scaling_") as out:
        command = [binary, scene, "--out", out, "--end", str(end), "--no-render",
                   "--set", "mesh.segments=%d" % segments, "--set", "mesh.rings=%d" % rings,
                   "--set", "output.obj=false", "--set", "collision.self=%s" % ("true" if contact else "false")]
        for s in extra_sets:
            command += ["--set", s]
        load = os.getloadavg()[0]
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(process.pid, 0)
        stderr = process.stderr.read().decode(errors="replace")
        process.stderr.close()
        if os.waitstatus_to_exitcode(status) != 0:
            die("%s failed (exit %d): %s" % (" ".join(command), os.waitstatus_to_exitcode(status), stderr[-2000:]))
        folder = os.path.join(out, "sleeve_compress_2542")
        summary = json.load(open(os.path.join(folder, "summary.json")))
        with open(os.path.join(folder, "stats.csv")) as f:
            rows = list(csv.DictReader(f))
    steps = len(rows)
    seconds = summary["seconds"]
    per_step = lambda total_seconds: 1000.0 * total_seconds / steps
    return {
        "segments": segments, "rings": rings, "steps": steps,
        "ms_per_step": per_step(seconds["rotate"] + seconds["assemble"] + seconds["solve"]),
        "rotate_ms": per_step(seconds["rotate"]), "assemble_ms": per_step(seconds["assemble"]),
        "solve_ms": per_step(seconds["solve"]),
        "factor_ms": sum(float(r["factor_ms"]) for r in rows) / steps,
        "factorizations": sum(int(r["factorizations"]) for r in rows) / steps,
        "iterations": sum(int(r["solver_iterations"]) for r in rows) / steps,
        "contact_ms": per_step(summary["contact"]["seconds"]) if "contact" in summary else 0.0,
        "wall_seconds": summary["wall_seconds"],
        "peak_rss_MiB": usage.ru_maxrss / 1024.0,
        "load_1min": load,
    }


def vertices_of(segments, rings):
    return segments * rings  # the cylinder primitive: a ring of `segments` vertices per ring


def run(args):
    binary, out_csv, label, sizes, end, repeats, contact, sets = None, None, "run", DEFAULT_SIZES, 0.2, 3, False, []
    scene = SCENE
    i = 0
    while i < len(args):
        a = args[i]
        value = lambda: args[i + 1] if i + 1 < len(args) else die(a + " needs a value")
        if a == "--bin": binary = value(); i += 2
        elif a == "--csv": out_csv = value(); i += 2
        elif a == "--label": label = value(); i += 2
        elif a == "--sizes": sizes = value(); i += 2
        elif a == "--end": end = float(value()); i += 2
        elif a == "--repeats": repeats = int(value()); i += 2
        elif a == "--set": sets.append(value()); i += 2
        elif a == "--scene": scene = value(); i += 2
        elif a == "--contact": contact = True; i += 1
        else: die("unknown option " + a)
    if not binary or not out_csv:
        die("run needs --bin and --csv")
    new_file = not os.path.exists(out_csv)
    with open(out_csv, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        if new_file:
            writer.writeheader()
        for repeat in range(repeats):
            for segments, rings in parse_sizes(sizes):
                row = one_run(binary, scene, segments, rings, end, contact, sets)
                row.update(label=label, repeat=repeat, vertices=vertices_of(segments, rings))
                writer.writerow({k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items()})
                f.flush()
                sys.stderr.write("scaling.py: %s %dx%d repeat %d: %.2f ms/step, %.0f MiB\n" %
                                 (label, segments, rings, repeat, row["ms_per_step"], row["peak_rss_MiB"]))


def medians(paths):
    groups = {}
    for path in paths:
        with open(path) as f:
            for r in csv.DictReader(f):
                groups.setdefault((r["label"], int(r["vertices"])), []).append(r)
    result = []
    for (label, vertices), rows in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        m = {k: statistics.median(float(r[k]) for r in rows) for k in FIELDS[6:]}
        m.update(label=label, vertices=vertices, runs=len(rows), steps=int(rows[0]["steps"]),
                 spread=(min(float(r["ms_per_step"]) for r in rows), max(float(r["ms_per_step"]) for r in rows)))
        result.append(m)
    return result


def table(paths):
    print("| label | vertices | ms per step (min–max) | µs per vertex per step | rotate / assemble / solve ms (factorising) "
          "| iterations / step | factorisations / step | peak memory | bytes per vertex | runs |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    for m in medians(paths):
        print("| %s | %d | %.1f (%.1f–%.1f) | %.2f | %.2f / %.2f / %.1f (%.1f) | %.1f | %.2f | %.0f MiB | %.0f kB | %d |" % (
            m["label"], m["vertices"], m["ms_per_step"], m["spread"][0], m["spread"][1],
            1000.0 * m["ms_per_step"] / m["vertices"], m["rotate_ms"], m["assemble_ms"], m["solve_ms"], m["factor_ms"],
            m["iterations"], m["factorizations"], m["peak_rss_MiB"], m["peak_rss_MiB"] * 1048576 / m["vertices"] / 1000,
            m["runs"]))


def plot(out_png, paths):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = medians(paths)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    labels = sorted({m["label"] for m in rows})
    for label in labels:
        ms = [m for m in rows if m["label"] == label]
        v = [m["vertices"] for m in ms]
        ax[0].plot(v, [1000.0 * m["ms_per_step"] / m["vertices"] for m in ms], "o-", label=label)
        ax[1].plot(v, [m["peak_rss_MiB"] * 1048576 / m["vertices"] / 1000 for m in ms], "o-", label=label)
    if labels:  # linear cost within 1.5 times the smallest size's figure (issue 17's target)
        ms = [m for m in rows if m["label"] == labels[0]]
        base = 1000.0 * ms[0]["ms_per_step"] / ms[0]["vertices"]
        ax[0].axhline(1.5 * base, color="grey", linestyle="--", linewidth=1,
                      label="1.5 × %s at %d vertices" % (labels[0], ms[0]["vertices"]))
    ax[0].set_ylabel("µs per vertex per step (rotate + assemble + solve)")
    ax[1].set_ylabel("peak memory per vertex [kB]")
    for a in ax:
        a.set_xscale("log")
        a.set_xlabel("control vertices")
        a.set_ylim(bottom=0)
        a.grid(True, which="both", alpha=0.3)
        a.legend()
    fig.suptitle("Compressed sleeve, dt = 0.01 s, medians of repeated runs")
    fig.tight_layout()
    tmp = out_png + ".tmp.png"
    fig.savefig(tmp, dpi=90)
    os.replace(tmp, out_png)


def plot_command(args):
    if len(args) < 2:
        die("plot needs OUT.png and at least one CSV")
    plot(args[0], args[1:])


def main():
    return dispatch(__doc__, {"run": run, "table": table, "plot": plot_command})


if __name__ == "__main__":
    sys.exit(main())
