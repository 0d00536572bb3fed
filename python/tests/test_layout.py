# SPDX-License-Identifier: MIT
# Every struct the package declares with ctypes has the C compiler's size and field offsets.
import subprocess

from sdfccd import _lib


def test_struct_layouts_match_the_c_headers(layout_probe):
    out = subprocess.run([str(layout_probe)], check=True, capture_output=True, text=True).stdout
    c = {}
    for line in out.splitlines():
        name, value = line.split()
        c[name.replace(".pose.", ".")] = int(value)
    checked = 0
    structs = dict(_lib.STRUCTS)
    has_contact_h = "sdfccd_GuardParams" in c
    assert has_contact_h == _lib.HAVE_CONTACTS  # headers and library agree
    if has_contact_h:
        structs.update(_lib.CONTACT_STRUCTS)
    for cname, S in structs.items():
        assert c[cname] == _lib.C.sizeof(S), f"sizeof({cname}): C {c[cname]}, ctypes {_lib.C.sizeof(S)}"
        for f in S._fields_:
            key = f"{cname}.{f[0]}"
            assert c[key] == getattr(S, f[0]).offset, f"offsetof({key}): C {c[key]}, ctypes {getattr(S, f[0]).offset}"
            checked += 1
    assert checked == len(c) - len(structs)
