#!/usr/bin/env python3
"""The format and lint gates (docs/architecture.md, "Format and lint").

  scripts/lint.py --format                 clang-format: fails on any difference from .clang-format
  scripts/lint.py --tidy [-p BUILD] [-j N] clang-tidy (.clang-tidy) over the project's own translation units
                                           in BUILD/compile_commands.json (default build/dev): fails on any finding
  scripts/lint.py --fix                    applies clang-format to every C/C++ file git tracks, pending ones too
  --all                                    also check the files scripts/lint-pending.txt lists
  --only REGEX                             clang-tidy only the translation units whose path matches

Files are what git tracks (so nothing generated: the LCM headers live in the build tree). Both gates skip the
files scripts/lint-pending.txt lists (other branches are changing them; the lead formats them with --fix after
the merges, fixes their clang-tidy findings and empties the list). Exit codes: 0 clean, 1 findings, 64 usage.
"""
import argparse
import collections
import concurrent.futures
import fnmatch
import json
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".c")
# Our own code: every layer, the tests, the benchmarks and the examples (never the build tree's generated code).
OWN_DIRS = ("analysis", "auth", "bench", "can", "core", "daemon", "examples", "io", "lcm_types/include",
            "lcm_types/src", "sim", "tests", "tools")
WARNING = re.compile(r"^(/[^:]+):(\d+):(\d+): warning: (.*) \[([\w.,-]+)\]$")


def pending_patterns():
    path = os.path.join(ROOT, "scripts", "lint-pending.txt")
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8") as f:
        return [line.strip() for line in f if line.strip() and not line.startswith("#")]


def is_pending(rel, patterns):
    return any(fnmatch.fnmatch(rel, p) for p in patterns)


def tracked_sources():
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True, capture_output=True).stdout
    return [p for p in out.decode().split("\0") if p.endswith(SOURCE_SUFFIXES)]


def check_format(patterns):
    files = [f for f in tracked_sources() if not is_pending(f, patterns)]
    bad = []
    for f in files:
        with open(os.path.join(ROOT, f), encoding="utf-8") as src:
            before = src.read()
        after = subprocess.run(["clang-format", "--style=file", f], cwd=ROOT, check=True,
                               capture_output=True).stdout.decode()
        if before != after:
            bad.append(f)
    for f in bad:
        print(f"lint: format: {f} differs; clang-format --style=file {f} | diff {f} - shows how")
    print(f"lint: format: {len(files)} files checked, {len(bad)} differ from .clang-format "
          f"(scripts/lint.py --fix applies it)")
    return not bad


def fix_format():
    files = tracked_sources()
    for i in range(0, len(files), 40):
        subprocess.run(["clang-format", "-i", "--style=file", *files[i:i + 40]], cwd=ROOT, check=True)
    print(f"lint: clang-format applied to {len(files)} files; run scripts/lint.py --tidy, fix what it finds, and "
          f"drop the files it no longer finds anything in from scripts/lint-pending.txt")


def own_units(build, patterns, only):
    with open(os.path.join(build, "compile_commands.json"), encoding="utf-8") as f:
        entries = json.load(f)
    units = set()
    for e in entries:
        path = os.path.realpath(os.path.join(e["directory"], e["file"]))
        rel = os.path.relpath(path, ROOT)
        if rel.startswith("..") or not rel.startswith(tuple(d + "/" for d in OWN_DIRS)) or is_pending(rel, patterns):
            continue
        if only and not re.search(only, rel):
            continue
        units.add(path)
    return sorted(units)


def run_tidy(build, jobs, patterns, only):
    units = own_units(build, patterns, only)
    header_filter = "^" + re.escape(ROOT) + "/(" + "|".join(re.escape(d) for d in OWN_DIRS) + ")/"
    # -w: the compiler of record is g++ (-Werror there); clang's own warnings are not this gate's
    cmd = ["clang-tidy", "-p", build, "--quiet", "--extra-arg=-w",
           f"--header-filter={header_filter}"]

    def one(unit):
        r = subprocess.run([*cmd, unit], cwd=ROOT, capture_output=True, text=True)
        return unit, r.returncode, r.stdout, r.stderr

    start = time.monotonic()
    findings = {}  # (file, line, column, check) -> message; a header's finding once, whichever unit saw it
    failed = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for unit, code, out, err in pool.map(one, units):
            for line in out.splitlines():
                m = WARNING.match(line)
                if not m:
                    continue
                rel = os.path.relpath(m.group(1), ROOT)
                if is_pending(rel, patterns):
                    continue
                findings[(rel, int(m.group(2)), int(m.group(3)), m.group(5))] = m.group(4)
            if code != 0 and "error:" in out + err:
                failed.append(unit)
                print(out + err)
    per_check = collections.Counter(key[3] for key in findings)
    for (rel, line, col, check), msg in sorted(findings.items()):
        print(f"{rel}:{line}:{col}: {msg} [{check}]")
    for check, n in per_check.most_common():
        print(f"lint: tidy: {n:5d} {check}")
    print(f"lint: tidy: {len(units)} translation units in {time.monotonic() - start:.0f} s with {jobs} jobs: "
          f"{len(findings)} findings, {len(failed)} units that did not compile")
    return not findings and not failed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--format", action="store_true", help="check formatting")
    ap.add_argument("--tidy", action="store_true", help="run clang-tidy")
    ap.add_argument("--fix", action="store_true", help="apply clang-format to every tracked file")
    ap.add_argument("--all", action="store_true", help="also check the files scripts/lint-pending.txt lists")
    ap.add_argument("--only", help="clang-tidy only the translation units whose path matches this regex")
    ap.add_argument("-p", dest="build", default=os.path.join(ROOT, "build", "dev"), help="build tree")
    ap.add_argument("-j", dest="jobs", type=int, default=os.cpu_count() or 1, help="parallel clang-tidy runs")
    args = ap.parse_args()
    if not (args.format or args.tidy or args.fix):
        ap.print_usage(sys.stderr)
        return 64
    if args.fix:
        fix_format()
        return 0
    patterns = [] if args.all else pending_patterns()
    ok = True
    if args.format:
        ok = check_format(patterns) and ok
    if args.tidy:
        ok = run_tidy(os.path.abspath(args.build), args.jobs, patterns, args.only) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
