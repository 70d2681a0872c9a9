#!/usr/bin/env python3
"""The code a document quotes is the code that compiles: the lines between the `// [snippet]` markers
of an example must appear verbatim in a fenced block of the document.
    check_snippet.py EXAMPLE.cpp DOCUMENT.md"""
import sys

example, document = open(sys.argv[1]).read(), open(sys.argv[2]).read()
parts = example.split("// [snippet]\n")
if len(parts) != 3:
    sys.exit(f"{sys.argv[1]}: expected one region between two `// [snippet]` lines")
snippet = parts[1]
if "```cpp\n" + snippet + "```" not in document:
    sys.exit(f"{sys.argv[2]} does not quote the snippet of {sys.argv[1]} verbatim (in a ```cpp block):\n{snippet}")
print(f"check_snippet: {sys.argv[2]} quotes {sys.argv[1]} ({snippet.count(chr(10))} lines)")
