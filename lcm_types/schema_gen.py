#!/usr/bin/env python3
"""schema_gen.py — the second generator of lcm_types/: from each .lcm file, beside lcm-gen's classes, a
header rpem/mirror/<struct>.hpp with

  - rpem::mirror::<struct>: the message as plain data (no strings, no heap), for rpemd's queues and its
    real-time loop;
  - rpem::schema::Schema<rpem::<struct>>: the field list — name, LCM type, label, unit, group,
    documentation and a member pointer into lcm-gen's class and into the mirror — over which
    lcm_types/include/rpem/schema/ copies a mirror into the LCM message and prints and records messages
    as generic code (for_each_field, copy, format_fields, csv_header, csv_row).

So the .lcm file is the one definition of a message: adding a field is its line there (and the code that
computes its value). Why a generator of ours: lcm-gen writes classes, not field lists, and drops field
comments (units, labels, groups); parsing its C++ output would read a format that is no interface; X-macros
would make the C++ side one list but leave the .lcm file a second one, kept in step by hand. Per field this
writes a member and a table row only; what is done to fields is C++ templates over the table, written once.
More, and what it makes of a field: docs/architecture.md, "One definition per message".

    schema_gen.py --out DIR FILE.lcm...

The LCM subset it reads (anything else is an error naming file:line:column):
  package NAME;  one struct per file, named as lcm-gen names its header (rpem_<struct>.lcm);
  fields of the primitive types int8_t int16_t int32_t int64_t float double boolean byte string, one per
  declaration, optionally a fixed array `TYPE name[N];`; `const TYPE NAME = VALUE;`; // and /* */ comments.
What the comments mean here:
  - the comment before `struct` documents the struct;
  - a comment on a line of its own inside the struct opens a group (its first line, up to a colon, is the
    group's title): `rpem listen` separates groups with " | ";
  - a field's trailing comment documents it, continued on the lines right below that start in its column
    (not a group); a leading [label] there is the short name `rpem listen` shows
    and its CSV column (else the field's name) — unless an earlier field of the struct has that label: a
    key is unique, so the later field keeps its name (with a warning);
  - the unit is the name's suffix (_V _A _Wb _Ohm _rad _rad_s _Hz _C _s _us _ns _pu: the project's rule that
    every quantity names its unit).
Strings are not mirrored: each of ours names a configuration the real-time thread holds as an enum (the
algorithm) or the publisher's own identity (the source); the publisher spells them. The authentication
fields `int32_t key_id; byte mac[32];` must be a struct's last two: they are neither mirrored nor listed
(auth/ signs the encoding).
"""
import argparse
import os
import re
import sys
import textwrap

# LCM primitive type → the mirror's C++ type (None: not mirrored). lcm-gen's class has int8_t for boolean
# and uint8_t for byte; the mirror says bool, and copy() writes 0 or 1 as lcm-gen's encoder would.
MIRROR_TYPES = {
    "int8_t": "std::int8_t",
    "int16_t": "std::int16_t",
    "int32_t": "std::int32_t",
    "int64_t": "std::int64_t",
    "float": "float",
    "double": "double",
    "boolean": "bool",
    "byte": "std::uint8_t",
    "string": None,
}
# Name suffix → unit, longest first (_rad_s before _s, _us before _s).
UNITS = [("_rad_s", "rad/s"), ("_Ohm", "Ohm"), ("_rad", "rad"), ("_Wb", "Wb"), ("_Hz", "Hz"), ("_pu", "pu"),
         ("_us", "us"), ("_ns", "ns"), ("_s", "s"), ("_C", "C"), ("_A", "A"), ("_V", "V")]
AUTH_FIELDS = [("key_id", "int32_t", None), ("mac", "byte", 32)]


class SchemaError(Exception):
    pass


class Token:
    def __init__(self, kind, text, line, col):
        self.kind, self.text, self.line, self.col = kind, text, line, col


class Comment:
    def __init__(self, text, line, standalone, col):
        self.text, self.line, self.standalone, self.col = text, line, standalone, col


TOKEN = re.compile(r"(?P<comment>//[^\n]*|/\*.*?\*/)|(?P<ident>[A-Za-z_][A-Za-z0-9_]*)|"
                   r"(?P<number>-?(?:0[xX][0-9a-fA-F]+|[0-9]+(?:\.[0-9]*)?(?:[eE][-+]?[0-9]+)?))|"
                   r"(?P<punct>[{}\[\];=,.])", re.S)


def tokenize(path, text):
    """Code tokens, and comments each marked standalone (nothing but blanks before it on its line)."""
    tokens, comments = [], []
    pos, line, line_start = 0, 1, 0
    code_on_line = False
    while True:
        while pos < len(text) and text[pos].isspace():
            if text[pos] == "\n":
                line, line_start, code_on_line = line + 1, pos + 1, False
            pos += 1
        if pos == len(text):
            return tokens, comments
        m = TOKEN.match(text, pos)
        col = pos - line_start + 1
        if not m:
            raise SchemaError(f"{path}:{line}:{col}: unexpected '{text[pos]}'")
        value = m.group(m.lastgroup)
        if m.lastgroup == "comment":
            body = value[2:] if value.startswith("//") else value[2:-2]
            comments.append(Comment(body, line, not code_on_line, col))
            if "\n" in value:
                line += value.count("\n")
                line_start = pos + value.rfind("\n") + 1
        else:
            tokens.append(Token(m.lastgroup, value, line, col))
            code_on_line = True
        pos = m.end()


class Field:
    def __init__(self, lcm_type, name, size, line, doc, label, group):
        self.lcm_type, self.name, self.size, self.line = lcm_type, name, size, line
        self.doc, self.label, self.group = doc, label, group
        self.unit = next((u for suffix, u in UNITS if name.endswith(suffix) and len(name) > len(suffix)), "")


class Struct:
    def __init__(self, package, name, doc):
        self.package, self.name, self.doc = package, name, doc
        self.fields, self.consts = [], []
        self.authenticated = False


class Parser:
    def __init__(self, path, text):
        self.path = path
        self.tokens, self.comments = tokenize(path, text)
        self.k = 0

    def error(self, token, what):
        where = f"{self.path}:{token.line}:{token.col}" if token else f"{self.path}: at the end"
        raise SchemaError(f"{where}: {what}")

    def peek(self):
        return self.tokens[self.k] if self.k < len(self.tokens) else None

    def take(self, kind=None, text=None, what=None):
        t = self.peek()
        if t is None or (kind and t.kind != kind) or (text and t.text != text):
            self.error(t, f"expected {what or text or kind}" + (f", found '{t.text}'" if t else ""))
        self.k += 1
        return t

    def comments_between(self, first_line, last_line, standalone):
        return [c for c in self.comments if first_line <= c.line <= last_line and c.standalone == standalone]

    def continuation(self, trailing):
        """The lines that continue a field's trailing comment: comments on lines of their own, one right after
        another from the line below it, each starting in the trailing comment's column."""
        if not trailing:
            return []
        out, line, col = [], trailing[-1].line + 1, trailing[-1].col
        while True:
            below = [c for c in self.comments if c.line == line and c.standalone and c.col == col]
            if not below:
                return out
            out += below
            line += 1

    def parse(self):
        self.take("ident", "package")
        package = self.take("ident", what="a package name").text
        while self.peek() and self.peek().text == ".":
            self.take("punct", ".")
            package += "." + self.take("ident").text
        self.take("punct", ";")
        structs = []
        prev_line = self.tokens[self.k - 1].line
        while self.peek():
            keyword = self.take("ident", "struct", what="'struct'")
            doc = " ".join(c.text.strip() for c in self.comments_between(prev_line + 1, keyword.line - 1, True))
            structs.append(self.parse_struct(package, doc))
            prev_line = self.tokens[self.k - 1].line
        if len(structs) != 1:
            self.error(None, f"{len(structs)} structs: one per file (lcm_types/CMakeLists.txt names each "
                             "header after its file, as lcm-gen does)")
        return structs[0]

    def parse_struct(self, package, doc):
        s = Struct(package, self.take("ident", what="a struct name").text, doc)
        open_brace = self.take("punct", "{")
        group, last_line = "", open_brace.line
        while self.peek() and self.peek().text != "}":
            first = self.peek()
            # A comment on a line of its own since the last declaration opens a group: its first line names it.
            blocks = self.comments_between(last_line + 1, first.line - 1, True)
            if blocks:
                group = blocks[0].text.strip().split(":")[0].strip()
            if first.text == "const":
                self.parse_const(s)
                last_line = self.tokens[self.k - 1].line
            else:
                last_line = self.parse_field(s, group)
        self.take("punct", "}", what="'}'")
        self.check_authentication(s)
        return s

    def parse_type(self):
        t = self.take("ident", what="a type")
        if t.text not in MIRROR_TYPES:
            self.error(t, f"type '{t.text}' is not one of {' '.join(MIRROR_TYPES)} (nested types are not read here)")
        return t.text

    def parse_const(self, s):
        self.take("ident", "const")
        lcm_type = self.parse_type()
        if lcm_type in ("string", "boolean", "byte"):
            self.error(self.tokens[self.k - 1], f"a const of type {lcm_type}")
        while True:
            name = self.take("ident", what="a constant's name").text
            self.take("punct", "=")
            value = self.take("number", what="a number").text
            s.consts.append((lcm_type, name, value))
            if self.peek() and self.peek().text == ",":
                self.take("punct", ",")
                continue
            break
        self.take("punct", ";")

    def parse_field(self, s, group):
        lcm_type = self.parse_type()
        name_token = self.take("ident", what="a field name")
        size = None
        if self.peek() and self.peek().text == "[":
            self.take("punct", "[")
            dim = self.take(what="an array size")
            if dim.kind != "number" or not re.fullmatch(r"[0-9]+", dim.text) or int(dim.text) == 0:
                self.error(dim, "only fixed arrays of a positive literal size are read here (no variable length)")
            size = int(dim.text)
            self.take("punct", "]")
            if self.peek() and self.peek().text == "[":
                self.error(self.peek(), "multi-dimensional arrays are not read here")
        if lcm_type == "string" and size is not None:
            self.error(name_token, "an array of strings")
        end = self.take("punct", what="';' (one field per declaration)")
        if end.text != ";":
            self.error(end, "one field per declaration")
        trailing = self.comments_between(end.line, end.line, False)
        trailing += self.continuation(trailing)
        doc = " ".join(c.text.strip() for c in trailing)
        label = ""
        m = re.match(r"\[([^\]]+)\]\s*(.*)", doc)
        if m:
            label, doc = m.group(1).strip(), m.group(2)
        if any(f.name == name_token.text for f in s.fields):
            self.error(name_token, f"field '{name_token.text}' declared twice")
        if label and any(f.label == label for f in s.fields):
            # A label is a key of `rpem listen`'s line and a column of its CSV, which readers look up by
            # name: the first field to claim it keeps it, a later one is shown by its own name.
            print(f"{self.path}:{name_token.line}:{name_token.col}: warning: label [{label}] is taken by an "
                  f"earlier field; '{name_token.text}' keeps its name", file=sys.stderr)
            label = ""
        s.fields.append(Field(lcm_type, name_token.text, size, name_token.line, doc, label, group))
        return trailing[-1].line if trailing else end.line

    def check_authentication(self, s):
        auth_names = {name for name, _, _ in AUTH_FIELDS}
        if not any(f.name in auth_names for f in s.fields):
            return
        tail = [(f.name, f.lcm_type, f.size) for f in s.fields[-len(AUTH_FIELDS):]]
        if tail != AUTH_FIELDS:
            bad = next(f for f in s.fields if f.name in auth_names)
            raise SchemaError(f"{self.path}:{bad.line}:1: the authentication fields must be the last two, "
                              "'int32_t key_id; byte mac[32];' (auth/ signs the encoding up to the MAC)")
        s.fields = s.fields[:-len(AUTH_FIELDS)]
        s.authenticated = True


def cpp_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def generate(struct, source_name):
    """The header for one struct."""
    ns = struct.package.replace(".", "::")
    message = f"::{ns}::{struct.name}"
    mirror = f"::{ns}::mirror::{struct.name}"
    spelled = [f.name for f in struct.fields if MIRROR_TYPES[f.lcm_type] is None]
    out = [f"// Generated by lcm_types/schema_gen.py from lcm_types/{source_name}: do not edit. The .lcm file is",
           "// the definition (docs/architecture.md, \"One definition per message\").",
           "#pragma once", "",
           "#include <array>", "#include <cstdint>", "#include <string_view>", "#include <tuple>", "",
           f'#include "{struct.package.replace(".", "/")}/{struct.name}.hpp"',
           '#include "rpem/schema/field.hpp"', "",
           f"namespace {ns}::mirror {{", ""]
    not_here = []
    if spelled:
        not_here.append(", ".join(spelled) + " (strings: the publisher spells them)")
    if struct.authenticated:
        not_here.append("key_id, mac (authentication: the publisher signs the encoding)")
    doc = f"{struct.package}.{struct.name} as plain data, for queues and the real-time path. {struct.doc}"
    if not_here:
        doc += " Not here: " + "; ".join(not_here) + "."
    out += textwrap.wrap(doc, 110, initial_indent="/// ", subsequent_indent="/// ")
    out.append(f"struct {struct.name} {{")
    out.append(f"  using Message = {message};")
    for lcm_type, name, value in struct.consts:
        out.append(f"  static constexpr {MIRROR_TYPES[lcm_type]} {name} = {value};")
    group = None
    for f in struct.fields:
        cpp = MIRROR_TYPES[f.lcm_type]
        if cpp is None:
            continue
        if f.group != group and f.group:
            out.append(f"  // {f.group}")
        group = f.group
        doc = f"  ///< {f.doc}" if f.doc else ""
        if f.size is None:
            out.append(f"  {cpp} {f.name}{{}};{doc}")
        else:
            out.append(f"  std::array<{cpp}, {f.size}> {f.name}{{}};{doc}")
    out += ["};", "", f"}}  // namespace {ns}::mirror", "", "namespace rpem::schema {", "",
            "template <>", f"struct Schema<{message}> {{", f"  using Message = {message};", f"  using Mirror = {mirror};",
            f"  static constexpr std::string_view kName = {cpp_string(struct.package + '.' + struct.name)};",
            f"  static constexpr bool kAuthenticated = {'true' if struct.authenticated else 'false'};",
            "  static constexpr auto kFields = std::make_tuple("]
    rows = []
    for f in struct.fields:
        lcm_type = f.lcm_type if f.size is None else f"{f.lcm_type}[{f.size}]"
        info = (f"FieldInfo{{{cpp_string(f.name)}, {cpp_string(lcm_type)}, {cpp_string(f.label)}, {cpp_string(f.unit)}, "
                f"{cpp_string(f.group)}, {cpp_string(f.doc)}}}")
        if MIRROR_TYPES[f.lcm_type] is None:
            rows.append(f"      spelled({info}, &Message::{f.name})")
        else:
            rows.append(f"      mirrored({info}, &Message::{f.name}, &Mirror::{f.name})")
    out.append(",\n".join(rows) + ");")
    out += ["};", "", "}  // namespace rpem::schema", ""]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="include root: writes OUT/rpem/mirror/<struct>.hpp")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    try:
        for path in a.files:
            with open(path, encoding="utf-8") as f:
                struct = Parser(path, f.read()).parse()
            stem = os.path.splitext(os.path.basename(path))[0]
            if stem != f"{struct.package.split('.')[0]}_{struct.name}":
                raise SchemaError(f"{path}:1:1: struct {struct.name} in a file not named "
                                  f"{struct.package.split('.')[0]}_{struct.name}.lcm")
            directory = os.path.join(a.out, *struct.package.split("."), "mirror")
            os.makedirs(directory, exist_ok=True)
            target = os.path.join(directory, struct.name + ".hpp")
            text = generate(struct, os.path.basename(path))
            # Rewritten only when it changes: what includes it is not rebuilt for nothing.
            old = None
            if os.path.exists(target):
                with open(target, encoding="utf-8") as f:
                    old = f.read()
            if old != text:
                with open(target, "w", encoding="utf-8") as f:
                    f.write(text)
    except (SchemaError, OSError) as e:
        print(f"schema_gen: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
