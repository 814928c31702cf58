"""The ctypes structs match the C headers (sizes and offsets printed by the C compiler)."""
import ctypes

from fesd import _lib


def test_struct_layout(reference):
    rec = reference("layout")
    assert rec["sizes"], "no layout printed"
    for cname, size in rec["sizes"].items():
        assert ctypes.sizeof(_lib.STRUCTS[cname]) == size, cname
    for key, off in rec["offsets"].items():
        cname, field = key.split(".")
        field = {"lambda": "lambda_"}.get(field, field)
        assert getattr(_lib.STRUCTS[cname], field).offset == off, key
    assert len(rec["offsets"]) >= 40


def test_status_strings():
    assert _lib.status_name(-6) == "FESD_ERR_CALLBACK"
    assert _lib.status_name(1) == "FESD_ROOT"
    assert "callback" in _lib.status_string(-6)
