#!/usr/bin/env python3
"""Recomputes the HMAC test vector in test_mac.cpp independently of rpem's C++: the LCM encoding from
LCM's own Python generator (lcm-gen --python, run on lcm_types/rpem_command_t.lcm into a temporary
directory) and the tag from Python's hmac/hashlib, per the definition in auth/include/rpem/auth/mac.hpp:
    mac = HMAC-SHA256(key, b"rpem-auth-1" 0x00 channel 0x00 E[0, n-32))
Usage: make_test_vector.py [REPO]  — prints the encoding and the tag in hex."""
import hashlib
import hmac
import pathlib
import subprocess
import sys
import tempfile

repo = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2])
with tempfile.TemporaryDirectory() as d:
    subprocess.run(["lcm-gen", "--python", "--ppath", d, str(repo / "lcm_types/rpem_command_t.lcm")], check=True)
    sys.path.insert(0, d)
    from rpem import command_t

    m = command_t()
    m.utime, m.seq, m.command, m.psi_m_Wb, m.r_s_Ohm, m.key_id = 1700000000000000, 42, 4, 1.05, 2.4, 7
    m.mac = bytes(32)
    e = m.encode()
key = bytes(range(32))
tag = hmac.new(key, b"rpem-auth-1\x00" + b"RPEM_COMMAND" + b"\x00" + e[:-32], hashlib.sha256).digest()
print("encoding", e.hex())
print("tag", tag.hex())
