#!/usr/bin/env python3
"""The format and lint gates (docs/architecture.md, "Format and lint").

  scripts/lint.py --format                 clang-format check: fails on any difference from .clang-format,
                                           naming file:line of each place that differs
  scripts/lint.py --fix-format             rewrites every checked file with clang-format (the fix for --format)
  scripts/lint.py --tidy [-p BUILD] [-j N] clang-tidy (.clang-tidy) over the production translation units in
                                           BUILD/compile_commands.json (default build/dev) and the headers
                                           they include: fails on any finding, naming file:line and the check
                                           (a unity tree's batches: each batch one unit, its sources checked
                                           through it; --per-source: each source alone)
  --only REGEX                             clang-tidy only the units with a source whose path matches (a
                                           unity batch whole)
  --tests                                  clang-tidy the test, benchmark and example units too (not gated)

Files: what git tracks under our own directories (OWN_DIRS). Nothing generated (lcm-gen's and schema_gen.py's
headers live in the build tree), nothing under data/, no third-party code (none is vendored; were some added,
it goes in EXCLUDED). Exit codes: 0 clean, 1 findings, 64 usage.
"""
import argparse
import collections
import concurrent.futures
import fnmatch
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".c")
# Our own code: every layer, the tests, the benchmarks and the examples (never the build tree's generated code).
OWN_DIRS = ("analysis", "auth", "bench", "can", "core", "daemon", "examples", "io", "lcm_types/include",
            "lcm_types/src", "sim", "tests", "tools")
# What the clang-tidy gate covers: the code that ships (docs/benchmarks.md, "Format and lint gates", has the
# cost of the rest). Headers of these directories are checked through the units that include them.
PRODUCTION_DIRS = ("analysis", "auth", "can", "core", "daemon", "io", "lcm_types/include", "lcm_types/src", "sim",
                   "tools")
# fnmatch patterns never checked: recorded data, build trees, vendored or generated code.
EXCLUDED = ("data/*", "build/*", "*/third_party/*", "*/vendor/*", "*/generated/*")
WARNING = re.compile(r"^(/[^:]+):(\d+):(\d+): warning: (.*) \[([\w.,-]+)\]$")
FORMAT_WARNING = re.compile(r"^(.+):(\d+):(\d+): (?:warning|error): code should be clang-formatted")
# A unity build's batch (RPEM_UNITY_BUILD, CMakeLists.txt): CMake's generated file of #include lines, one a source
UNITY_BATCH = re.compile(r"/CMakeFiles/[^/]+\.dir/Unity/unity_\d+_cxx\.cxx$")
UNITY_INCLUDE = re.compile(r'^#include "(/[^"]+)"$', re.M)


def tool(name):
    """The Debian package's binary (scripts/setup.sh installs clang-format and clang-tidy, version 14)."""
    for candidate in (name, name + "-14"):
        if shutil.which(candidate):
            return candidate
    sys.exit(f"lint: {name} not found: scripts/setup.sh installs it (apt-get install {name})")


def is_own(rel, dirs=OWN_DIRS):
    return rel.startswith(tuple(d + "/" for d in dirs)) and not any(fnmatch.fnmatch(rel, p) for p in EXCLUDED)


def checked_sources():
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True, capture_output=True).stdout
    return [p for p in out.decode().split("\0") if p.endswith(SOURCE_SUFFIXES) and is_own(p)]


def batches(files, size=40):
    for i in range(0, len(files), size):
        yield files[i:i + size]


def check_format():
    files = checked_sources()
    places = collections.defaultdict(list)  # file -> lines that differ
    for batch in batches(files):
        r = subprocess.run([tool("clang-format"), "--dry-run", "--style=file", *batch], cwd=ROOT,
                           capture_output=True, text=True)
        for line in r.stderr.splitlines():
            m = FORMAT_WARNING.match(line)
            if m:
                rel = os.path.relpath(os.path.join(ROOT, m.group(1)), ROOT)
                if int(m.group(2)) not in places[rel]:
                    places[rel].append(int(m.group(2)))
    for rel, lines in sorted(places.items()):
        more = f" (and {len(lines) - 1} more lines)" if len(lines) > 1 else ""
        print(f"{rel}:{lines[0]}: not formatted as .clang-format says{more}")
    print(f"lint: format: {len(files)} files checked, {len(places)} differ from .clang-format, "
          f"{sum(len(v) for v in places.values())} lines. Fix: scripts/lint.py --fix-format (rewrites them); "
          f"one file: clang-format -i --style=file FILE")
    return not places


def fix_format():
    files = checked_sources()
    for batch in batches(files):
        subprocess.run([tool("clang-format"), "-i", "--style=file", *batch], cwd=ROOT, check=True)
    print(f"lint: clang-format applied to {len(files)} files (git diff --stat shows which changed)")


def tidy_units(build, per_source):
    """The units clang-tidy checks, as (file, its database directory, the sources it stands for). A tree without
    unity batches: each source. A unity tree (RPEM_UNITY_BUILD, CMakeLists.txt; scripts/test.sh builds build/ci
    so): each batch as one unit, the sources it includes checked through it as what it compiles, the shared
    headers parsed and matched once a batch instead of once a source — the same findings as each source alone
    wherever measured (defects of 20 checks of every enabled family; docs/benchmarks.md, "Format and lint
    gates", has both modes' cost). With
    per_source, each batch's sources alone under the batch's command (the one a source has without batches),
    from an expanded database in a scratch directory."""
    with open(os.path.join(build, "compile_commands.json"), encoding="utf-8") as f:
        entries = json.load(f)
    units, expanded = [], []
    for e in entries:
        path = os.path.realpath(os.path.join(e["directory"], e["file"]))
        if not UNITY_BATCH.search(path):
            units.append((path, build, [path]))
            expanded.append(e)
            continue
        with open(path, encoding="utf-8") as f:
            sources = [os.path.realpath(s) for s in UNITY_INCLUDE.findall(f.read())]
        if not sources:
            sys.exit(f"lint: {path}: a unity batch that includes no source (has CMake's format changed?)")
        units.append((path, build, sources))
        expanded += [{"directory": e["directory"], "file": s, "command": e["command"].replace(e["file"], s)}
                     for s in sources]
    if not per_source or len(expanded) == len(entries):
        return units, None
    scratch = tempfile.TemporaryDirectory(prefix="lint-tidy-")
    with open(os.path.join(scratch.name, "compile_commands.json"), "w", encoding="utf-8") as f:
        json.dump(expanded, f)
    return [(s, scratch.name, [s]) for _, _, sources in units for s in sources], scratch


def selected(units, dirs, only):
    """The units with a source of ours in dirs (matching only, if given); each file once."""
    chosen = {}
    for unit, database, sources in units:
        rels = [os.path.relpath(s, ROOT) for s in sources]
        if any(is_own(r, dirs) and (not only or re.search(only, r)) for r in rels):
            chosen[unit] = (unit, database, sources)
    return [chosen[u] for u in sorted(chosen)]


def is_batch_include(path, check):
    """A batch's own finding: CMake's #include of each source (a .cpp) is all a unity batch holds."""
    return check == "bugprone-suspicious-include" and UNITY_BATCH.search(path) is not None


def run_tidy(build, jobs, dirs, only, per_source):
    units, scratch = tidy_units(build, per_source)  # scratch: the expanded database, kept until the runs end
    units = selected(units, dirs, only)
    # The largest first (its sources' bytes, a proxy for its time: 2-30 s a unit), so that the run does not end on
    # one long unit with the other jobs idle
    units.sort(key=lambda u: sum(os.path.getsize(s) for s in u[2]), reverse=True)
    # A header's findings: only for our own headers (never Eigen's, Ceres's, gtest's or the generated ones); a
    # batch's sources are "headers" of the batch, so the same filter reports them
    header_filter = "^" + re.escape(ROOT) + "/(" + "|".join(re.escape(d) for d in OWN_DIRS) + ")/"
    # -w: the compiler of record is g++ (-Werror there); clang's own warnings are not this gate's
    cmd = [tool("clang-tidy"), "--quiet", "--extra-arg=-w", f"--header-filter={header_filter}"]

    def one(unit, database):
        r = subprocess.run([*cmd, "-p", database, unit], cwd=ROOT, capture_output=True, text=True)
        return unit, r.returncode, r.stdout, r.stderr

    start = time.monotonic()
    findings = {}  # (file, line, column, check) -> message; a header's finding once, whichever unit saw it
    failed = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for done in concurrent.futures.as_completed([pool.submit(one, u, db) for u, db, _ in units]):
            unit, code, out, err = done.result()
            for line in out.splitlines():
                m = WARNING.match(line)
                if not m or is_batch_include(m.group(1), m.group(5)):
                    continue
                key = (os.path.relpath(m.group(1), ROOT), int(m.group(2)), int(m.group(3)), m.group(5))
                if key not in findings:  # printed as found, so a long run's log shows them early
                    findings[key] = m.group(4)
                    print(f"{key[0]}:{key[1]}:{key[2]}: {m.group(4)} [{key[3]}]", flush=True)
            if code != 0 and "error:" in out + err:
                failed.append(unit)
                print(out + err, flush=True)
    per_check = collections.Counter(key[3] for key in findings)
    for check, n in per_check.most_common():
        print(f"lint: tidy: {n:5d} {check}")
    if findings or failed:
        print("lint: tidy: fix each place above (docs/architecture.md, \"Format and lint\": a NOLINT only with its "
              "reason on the same line); again locally: scripts/lint.py --tidy -p BUILD [--only REGEX]")
    sources = sum(len(s) for _, _, s in units)
    print(f"lint: tidy: {len(units)} translation units ({sources} sources) in {time.monotonic() - start:.0f} s "
          f"with {jobs} jobs: {len(findings)} findings, {len(failed)} units that did not compile")
    return not findings and not failed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--format", action="store_true", help="check formatting")
    ap.add_argument("--fix-format", action="store_true", help="apply clang-format to every checked file")
    ap.add_argument("--tidy", action="store_true", help="run clang-tidy")
    ap.add_argument("--only", help="clang-tidy only the units with a source whose path matches this regex")
    ap.add_argument("--tests", action="store_true", help="clang-tidy the tests, benchmarks and examples too")
    ap.add_argument("--per-source", action="store_true",
                    help="in a unity tree, clang-tidy each batch's sources alone (the same findings, slower)")
    ap.add_argument("-p", dest="build", default=os.path.join(ROOT, "build", "dev"), help="build tree")
    ap.add_argument("-j", dest="jobs", type=int, default=os.cpu_count() or 1, help="parallel clang-tidy runs")
    args = ap.parse_args()
    if not (args.format or args.tidy or args.fix_format):
        ap.print_usage(sys.stderr)
        return 64
    if args.fix_format:
        fix_format()
        return 0
    ok = True
    if args.format:
        ok = check_format() and ok
    if args.tidy:
        dirs = OWN_DIRS if args.tests else PRODUCTION_DIRS
        ok = run_tidy(os.path.abspath(args.build), args.jobs, dirs, args.only, args.per_source) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
