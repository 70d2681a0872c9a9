#!/usr/bin/env python3
"""What must not compile does not: CASE.cpp compiles as it is (the control: the right way to do it) and
fails to compile with -DRPEM_COMPILE_FAIL (the wrong way), for the reason REGEX names in the compiler's
message — so a typo or a missing include cannot pass for the guarantee.
    expect_compile_error.py CXX CASE.cpp REGEX [compiler flags...]"""
import re
import subprocess
import sys

cxx, case, reason, *flags = sys.argv[1:]


def compile(extra):
    command = [cxx, "-std=c++20", "-fsyntax-only", "-Wall", "-Wextra", "-Werror", *flags, *extra, case]
    return subprocess.run(command, capture_output=True, text=True)


control = compile([])
if control.returncode != 0:
    sys.exit(f"{case}: the control does not compile:\n{control.stderr}")
wrong = compile(["-DRPEM_COMPILE_FAIL"])
if wrong.returncode == 0:
    sys.exit(f"{case}: compiles with RPEM_COMPILE_FAIL; it must not")
if not re.search(reason, wrong.stderr):
    sys.exit(f"{case}: does not compile, but not for the reason expected (/{reason}/):\n{wrong.stderr}")
print(f"{case}: the control compiles; RPEM_COMPILE_FAIL does not (/{reason}/)")
