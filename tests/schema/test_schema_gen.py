#!/usr/bin/env python3
"""lcm_types/schema_gen.py: what it reads from a .lcm file (labels, units, groups, authentication, arrays,
constants), and the .lcm files it refuses, each naming file:line:column and why.

    test_schema_gen.py SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile
import unittest

SOURCE_DIR = sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
GENERATOR = os.path.join(SOURCE_DIR, "lcm_types", "schema_gen.py")

GOOD = """package rpem;

// PROBE: a struct of every kind of field.
struct probe_t
{
    int64_t utime;
    double  psi_m_Wb;                  // [psi_m] flux
    double  omega_el_rad_s;

    // Counters: grow
    int64_t can_frames_lost;           // [lost] frames lost
    boolean ok;
    int16_t counts[3];                 // per phase
    string  name;                      // spelled by the sender

    const int8_t ONE = 1, TWO = 2;

    // Authentication: the last two
    int32_t key_id;
    byte    mac[32];
}
"""


def run(text, name="rpem_probe_t.lcm"):
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, name)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        p = subprocess.run([sys.executable, GENERATOR, "--out", d, path], capture_output=True, text=True)
        header = os.path.join(d, "rpem", "mirror", "probe_t.hpp")
        out = None
        if os.path.exists(header):
            with open(header, encoding="utf-8") as f:
                out = f.read()
        return p.returncode, p.stderr.replace(d + os.sep, ""), out


class Reads(unittest.TestCase):
    def test_labels_units_groups_arrays_constants_and_authentication(self):
        code, err, out = run(GOOD)
        self.assertEqual(code, 0, err)
        self.assertIn('mirrored(FieldInfo{"psi_m_Wb", "double", "psi_m", "Wb", "", "flux"}', out)
        self.assertIn('FieldInfo{"omega_el_rad_s", "double", "", "rad/s", "", ""}', out)
        self.assertIn('FieldInfo{"can_frames_lost", "int64_t", "lost", "", "Counters", "frames lost"}', out)
        self.assertIn('FieldInfo{"counts", "int16_t[3]", "", "", "Counters", "per phase"}', out)
        self.assertIn("std::array<std::int16_t, 3> counts{};", out)
        self.assertIn("bool ok{};", out)
        self.assertIn('spelled(FieldInfo{"name", "string"', out)
        self.assertNotIn(" name{}", out)  # strings are not mirrored
        self.assertIn("static constexpr std::int8_t ONE = 1;", out)
        self.assertIn("static constexpr std::int8_t TWO = 2;", out)
        self.assertIn("kAuthenticated = true", out)
        self.assertNotIn('"key_id"', out)
        self.assertNotIn("mac", out.split("struct probe_t {")[1].split("};")[0])
        self.assertIn("PROBE: a struct of every kind of field.", out)

    def test_a_struct_without_authentication(self):
        code, err, out = run("package rpem;\nstruct probe_t { double x_V; int32_t key_count; }\n")
        self.assertEqual(code, 0, err)
        self.assertIn("kAuthenticated = false", out)
        self.assertIn('"x_V", "double", "", "V"', out)

    def test_a_trailing_comment_continued_in_its_column_is_the_fields_doc_not_a_group(self):
        # The lines right below a field's comment, starting in its column, continue it; a comment line after a
        # blank line, or in another column, opens a group as before.
        code, err, out = run("package rpem;\nstruct probe_t {\n"
                             "    // Counters: grow\n"
                             "    int64_t held;   // [held] steps refused as held:\n"
                             "                    // unchanged while the network moved\n"
                             "                    // by more than the gate\n"
                             "    int64_t other;  // one line\n"
                             "    // not a continuation: a group of its own\n"
                             "    int64_t next;\n"
                             "\n"
                             "    // Transport: frames\n"
                             "    int64_t frames;\n}\n")
        self.assertEqual(code, 0, err)
        self.assertIn('FieldInfo{"held", "int64_t", "held", "", "Counters", "steps refused as held: unchanged while '
                      'the network moved by more than the gate"}', out)
        self.assertIn('FieldInfo{"other", "int64_t", "", "", "Counters", "one line"}', out)
        self.assertIn('FieldInfo{"next", "int64_t", "", "", "not a continuation", ""}', out)
        self.assertIn('FieldInfo{"frames", "int64_t", "", "", "Transport", ""}', out)


class Refuses(unittest.TestCase):
    def refused(self, text, where, why, name="rpem_probe_t.lcm"):
        code, err, out = run(text, name)
        self.assertNotEqual(code, 0)
        self.assertIsNone(out)
        self.assertIn(where, err)
        self.assertIn(why, err)

    def test_a_missing_semicolon(self):
        self.refused("package rpem;\nstruct probe_t {\n  double x\n  double y;\n}\n", "rpem_probe_t.lcm:4:3:", "expected ';'")

    def test_a_variable_length_array(self):
        self.refused("package rpem;\nstruct probe_t {\n  int32_t n;\n  double x[n];\n}\n", "rpem_probe_t.lcm:4:12:",
                     "fixed arrays of a positive literal size")

    def test_a_nested_type(self):
        self.refused("package rpem;\nstruct probe_t {\n  other_t x;\n}\n", "rpem_probe_t.lcm:3:3:", "type 'other_t'")

    def test_two_fields_in_one_declaration(self):
        self.refused("package rpem;\nstruct probe_t {\n  double x, y;\n}\n", "rpem_probe_t.lcm:3:11:", "one field per declaration")

    def test_authentication_fields_not_last(self):
        self.refused("package rpem;\nstruct probe_t {\n  int32_t key_id;\n  byte mac[32];\n  double x;\n}\n",
                     "rpem_probe_t.lcm:3:1:", "must be the last two")

    def test_a_duplicate_field(self):
        self.refused("package rpem;\nstruct probe_t {\n  double x;\n  double x;\n}\n", "rpem_probe_t.lcm:4:10:", "declared twice")

    def test_a_label_taken_by_an_earlier_field(self):
        code, err, out = run("package rpem;\nstruct probe_t {\n  double t_C;  // [T] raw\n  double u_C;  // [T] fused\n}\n")
        self.assertEqual(code, 0, err)
        self.assertIn("rpem_probe_t.lcm:4:10: warning: label [T] is taken by an earlier field; 'u_C' keeps its name", err)
        self.assertIn('FieldInfo{"t_C", "double", "T", "C", "", "raw"}', out)
        self.assertIn('FieldInfo{"u_C", "double", "", "C", "", "fused"}', out)

    def test_two_structs_in_one_file(self):
        self.refused("package rpem;\nstruct probe_t { double x; }\nstruct other_t { double y; }\n", "rpem_probe_t.lcm",
                     "one per file")

    def test_a_file_not_named_after_its_struct(self):
        self.refused("package rpem;\nstruct probe_t { double x; }\n", "rpem_other_t.lcm:1:1:", "not named rpem_probe_t.lcm",
                     name="rpem_other_t.lcm")

    def test_a_stray_character(self):
        self.refused("package rpem;\nstruct probe_t {\n  double x; @\n}\n", "rpem_probe_t.lcm:3:13:", "unexpected '@'")


if __name__ == "__main__":
    unittest.main()
