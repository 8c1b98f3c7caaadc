#!/usr/bin/env python3
"""The measured numbers in one place: docs/measured.json (the record) and docs/measured.md (its
rendering, for people). README.md, docs/ and .github/workflows/ci.yml quote them or point here, and
tests/it/measured_numbers.rs fails when a quote no longer agrees with docs/measured.json.

  scripts/measured.py test --time-log FILE --load LOAD [--command CMD]
      make test's numbers from what it leaves in target/ (test-started, test-compiled,
      test-finished, test-commit, test-steps, test-beside, test-counts, test-summary) and the wall time and peak
      resident set of the whole command as `/usr/bin/time -v -o FILE CMD` reports them (run it
      on a fresh clone: `mkdir -p target && /usr/bin/time -v -o target/time.txt .ci/run`);
      --build-time-log FILE: `/usr/bin/time -v -o FILE make build`, run first, for make build's
      own time. `make measured` calls it.
  scripts/measured.py drift --time-log FILE --load LOAD --commit C --date YYYY-MM-DD
      `make drift`'s wall time and peak (`/usr/bin/time -v -o FILE make drift`).
  scripts/measured.py disk --date YYYY-MM-DD --commit C
      the disk a fresh clone uses after make test: target/ and crosscheck/.venv (du).
  scripts/measured.py render [--check]
      docs/measured.md from docs/measured.json (--check: exit 1 if it differs).

Units: KiB as /usr/bin/time reports them (1024 bytes); GiB = KiB / 1048576; GB = 1e9 bytes.
LOAD says what else the machine did: "idle", "nearly idle" or "under load" (what ran beside).
Nothing here is typed in by hand but LOAD (and a date or commit where no run recorded one)."""

import argparse
import json
import os
import re
import subprocess
import sys
from datetime import datetime, timezone

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
JSON = os.path.join(ROOT, "docs", "measured.json")
MD = os.path.join(ROOT, "docs", "measured.md")
TARGET = os.path.join(ROOT, "target")  # make test writes its numbers there, whatever CARGO_TARGET_DIR
NOTE = "Written by scripts/measured.py (make measured); rendered into docs/measured.md. Do not edit by hand."


def gib(kib):
    return f"{kib / 1048576:.2f} GiB"


def gb(nbytes):
    return f"{nbytes / 1e9:.2f} GB"


def kib(n):
    return f"{n:,} KiB"


def mmss(seconds):
    return f"{seconds // 60}:{seconds % 60:02d}"


def time_log(path):
    """Wall seconds (rounded) and peak KiB from `/usr/bin/time -v` output."""
    text = open(path).read()
    m = re.search(r"Elapsed \(wall clock\) time.*?: (?:(\d+):)?(\d+):(\d+(?:\.\d+)?)", text)
    r = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    if not m or not r:
        sys.exit(f"{path}: no 'Elapsed (wall clock) time' or 'Maximum resident set size' line: is it /usr/bin/time -v output?")
    wall = int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3))
    return round(wall), int(r.group(1))


def target_file(name):
    path = os.path.join(TARGET, name)
    if not os.path.exists(path):
        sys.exit(f"{path} missing: run make test first (it writes its numbers under target/)")
    return open(path).read()


def pairs(text):
    out = {}
    for line in text.splitlines():
        if line.strip():
            key, value = line.rsplit(" ", 1)
            out[key] = int(value)
    return out


def load():
    return json.load(open(JSON)) if os.path.exists(JSON) else {"note": NOTE}


def save(data):
    data["note"] = NOTE
    with open(JSON, "w") as f:
        json.dump(data, f, indent=2)
        f.write("\n")
    with open(MD, "w") as f:
        f.write(render(data))


def cmd_test(a):
    started = int(target_file("test-started"))
    compiled = int(target_file("test-compiled"))
    finished = int(target_file("test-finished"))
    summary = target_file("test-summary").strip()
    m = re.fullmatch(r"(\d+) passed, (\d+) failed, (\d+) skipped", summary)
    if not m:
        sys.exit(f"target/test-summary: {summary!r} is not 'N passed, N failed, N skipped'")
    counts = pairs(target_file("test-counts"))
    wall, peak = time_log(a.time_log)
    data = load()
    data["make_test"] = {
        "date": datetime.fromtimestamp(started, timezone.utc).strftime("%Y-%m-%d"),
        "commit": target_file("test-commit").strip(),
        "load": a.load,
        "command": a.command,
        "result": "PASSED",
        "after_build_s": finished - started,
        "compiling_s": compiled - started,
        "checks_s": finished - compiled,
        "steps_s": pairs(target_file("test-steps")),
        # the steps scripts/beside.sh ran side by side (compiling_s holds the longest of them, not their sum)
        "beside": target_file("test-beside").split() if os.path.exists(os.path.join(TARGET, "test-beside")) else [],
        "tests": {"passed": int(m.group(1)), "failed": int(m.group(2)), "skipped": int(m.group(3)),
                  "integration": counts["integration"], "unit": counts["unit"], "doc": counts["doc"]},
        "wall_s": wall,
        "peak_kib": peak,
    }
    if a.build_time_log:
        data["make_test"]["make_build_s"] = time_log(a.build_time_log)[0]
    else:
        data["make_test"]["missing"] = "make build's own time (give --build-time-log)"
    save(data)


def cmd_drift(a):
    wall, peak = time_log(a.time_log)
    data = load()
    data["make_drift"] = {"date": a.date, "commit": a.commit, "load": a.load, "command": "make drift (signorini drift --deep)",
                          "wall_s": wall, "peak_kib": peak}
    save(data)


def cmd_figures(a):
    wall, peak = time_log(a.time_log)
    data = load()
    data["make_figures"] = {"date": a.date, "commit": a.commit, "load": a.load,
                            "command": "make figures (signorini-figures built in the figures profile, then run)",
                            "wall_s": wall, "peak_kib": peak}
    if a.build_s is not None:
        data["make_figures"]["build_s"] = a.build_s
    save(data)


def du(path):
    return int(subprocess.run(["du", "-s", "--block-size=1", path], capture_output=True, text=True, check=True).stdout.split()[0])


def cmd_disk(a):
    data = load()
    data["disk"] = {"date": a.date, "commit": a.commit, "after": a.after,
                    "target_bytes": du(TARGET), "venv_bytes": du(os.path.join(ROOT, "crosscheck", ".venv"))}
    save(data)


def peak_row(peak_kib, what="peak resident set (largest process)"):
    """A table row of a peak resident set in KiB, GiB and GB."""
    return f"| {what} | {kib(peak_kib)} = {gib(peak_kib)} = {gb(peak_kib * 1024)} |"


def render(d):
    out = ["# Measured numbers", "",
           "Generated from [`measured.json`](measured.json) by `scripts/measured.py` (`make measured` after a",
           "`make test` run timed with `/usr/bin/time -v`; see the script's header). README.md and the",
           "workflow quote these; `tests/it/measured_numbers.rs` checks that the quotes agree. KiB as",
           "`/usr/bin/time` reports them (1024 bytes), GiB = KiB / 1048576, GB = 1e9 bytes.", ""]
    t = d.get("make_test")
    if t:
        s = t["steps_s"]
        out += ["## make test", "",
                f"{t['date']}, commit {t['commit']}, machine {t['load']}, run by `{t['command']}` on a fresh clone.", "",
                "| what | measured |", "| --- | --- |",
                *([f"| make build | {mmss(t['make_build_s'])} |"] if "make_build_s" in t else []),
                f"| make test, after make build | {t['result']} in {t['after_build_s']} s |",
                f"| compiling and installing | {t['compiling_s']} s |",
                f"| checks | {t['checks_s']} s |",
                "| seconds per step | " + ", ".join(f"{k} {v}" for k, v in s.items())
                + (f" ({', '.join(t['beside'])} side by side)" if t.get("beside") else "") + " |"]
        n = t["tests"]
        if n.get("passed") is not None:
            out.append(f"| cargo test's last line | {n['passed']} passed, {n['failed']} failed, {n['skipped']} skipped |")
        out.append(f"| tests run | {n['integration']} integration, {n['unit']} unit, {n['doc']} doc |")
        out.append(f"| `{t['command']}` in all | {mmss(t['wall_s'])} wall |")
        out.append(peak_row(t['peak_kib'], "its peak resident set (largest process)"))
        if "missing" in t:
            out += ["", "Not measured in this run: " + t["missing"] + "."]
        out.append("")
    r = d.get("make_drift")
    if r:
        out += ["## make drift", "",
                f"{r['date']}, commit {r['commit']}, machine {r['load']}: `{r['command']}`.", "",
                "| what | measured |", "| --- | --- |",
                f"| wall | {mmss(r['wall_s'])} |",
                peak_row(r['peak_kib']), ""]
    f = d.get("make_figures")
    if f:
        out += ["## make figures", "",
                f"{f['date']}, commit {f['commit']}, machine {f['load']}, on a fresh clone (nothing compiled): `{f['command']}`.", "",
                "| what | measured |", "| --- | --- |",
                f"| wall, clone to figures | {mmss(f['wall_s'])} |",
                *([f"| of which compiling (cargo build's Finished line) | {f['build_s']} s |"] if "build_s" in f else []),
                peak_row(f['peak_kib']), ""]
    k = d.get("disk")
    if k:
        out += ["## Disk", "",
                f"{k['date']}, commit {k['commit']}, {k['after']} (`du -s --block-size=1`).", "",
                "| what | measured |", "| --- | --- |",
                f"| target/ | {gb(k['target_bytes'])} |",
                f"| crosscheck/.venv | {gb(k['venv_bytes'])} |",
                f"| both | {gb(k['target_bytes'] + k['venv_bytes'])} |", ""]
    return "\n".join(out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("test")
    t.add_argument("--time-log", required=True)
    t.add_argument("--load", required=True, choices=["idle", "nearly idle", "under load"])
    t.add_argument("--command", default=".ci/run")
    t.add_argument("--build-time-log", help="/usr/bin/time -v make build, run before make test")
    r = sub.add_parser("drift")
    r.add_argument("--time-log", required=True)
    r.add_argument("--load", required=True, choices=["idle", "nearly idle", "under load"])
    r.add_argument("--commit", required=True)
    r.add_argument("--date", required=True)
    g = sub.add_parser("figures", help="/usr/bin/time -v make figures on a fresh clone")
    g.add_argument("--time-log", required=True)
    g.add_argument("--load", required=True, choices=["idle", "nearly idle", "under load"])
    g.add_argument("--commit", required=True)
    g.add_argument("--date", required=True)
    g.add_argument("--build-s", type=int, help="cargo build's own seconds (its Finished line)")
    k = sub.add_parser("disk")
    k.add_argument("--date", required=True)
    k.add_argument("--commit", required=True)
    k.add_argument("--after", default="after make test and make cluster-test (.ci/run)")
    c = sub.add_parser("render")
    c.add_argument("--check", action="store_true")
    a = p.parse_args()
    if a.cmd == "test":
        cmd_test(a)
    elif a.cmd == "drift":
        cmd_drift(a)
    elif a.cmd == "figures":
        cmd_figures(a)
    elif a.cmd == "disk":
        cmd_disk(a)
    elif a.check:
        if open(MD).read() != render(load()):
            sys.exit("docs/measured.md is not the rendering of docs/measured.json: run scripts/measured.py render")
    else:
        save(load())


if __name__ == "__main__":
    main()
