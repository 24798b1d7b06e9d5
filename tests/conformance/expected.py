#!/usr/bin/env python3
"""Expected values of vista's host-layer conformance probes, derived from
the WGSL and WebGPU specifications (never from vista, never blessed).

    python3 expected.py          # writes expected.toml beside this file
    python3 expected.py --check  # exits 1 if expected.toml is not what it would write

WGSL 13.4 (memory layout): AlignOf/SizeOf of scalars, vectors, matrices,
arrays and structures; a runtime-sized array's element stride is
roundUp(AlignOf(E), SizeOf(E)). WGSL 17.3 (arrayLength): the number of
elements that fit in the binding, floor((binding size - offset) / stride).
WebGPU: a buffer binding without an explicit size covers the buffer; vista
makes each buffer with exactly its declared bytes.
"""
import struct
import sys
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent


def round_up(k, n):
    return -(-n // k) * k


# WGSL 13.4.1: (align, size) of host-shareable types.
def scalar():
    return (4, 4)


def vec(n):
    return {2: (8, 8), 3: (16, 12), 4: (16, 16)}[n]


def mat(c, r):
    a, s = vec(r)
    return (a, c * round_up(a, s))  # an array of C column vectors


def array(elem, n):
    a, s = elem
    return (a, n * round_up(a, s))


def struct_of(members):
    """members: list of (align, size); returns (align, size)."""
    offset, align = 0, 1
    for a, s in members:
        offset = round_up(a, offset) + s
        align = max(align, a)
    return (align, round_up(align, offset))


def stride(elem):
    a, s = elem
    return round_up(a, s)


def array_length_probes():
    # The element types of shaders/array_length.wgsl, as the spec sizes them.
    elements = {
        "a4 array<u32>": scalar(),
        "a8 array<vec2<f32>>": vec(2),
        "a12 array<Three {f32, u32, f32}>": struct_of([scalar(), scalar(), scalar()]),
        "a16 array<vec3<f32>>": vec(3),
        "a32 array<Padded {vec3<f32>, f32, vec2<f32>}>": struct_of([vec(3), scalar(), vec(2)]),
        "a48 array<Basis {mat3x3<f32>}>": struct_of([mat(3, 3)]),
    }
    strides = [stride(e) for e in elements.values()]
    assert strides == [4, 8, 12, 16, 32, 48], strides
    seen_len = 8  # `lengths` is declared with 8 u32
    probes = []
    for n in range(1, 10):
        # Each buffer is declared with n elements: n * stride bytes bound.
        words = [(n * s) // s for s in strides] + [(seen_len * 4) // 4, 0xA11]
        probes.append({
            "kernel": "array_length", "set": {"n": n}, "output": "lengths", "words": words,
            "why": f"strides {strides}, {n} elements declared: arrayLength = floor({n} * stride / stride) = {n}; "
                   f"the output itself {seen_len}; then the marker 0xA11",
        })
    return probes


# The leaves of shaders/layout.wgsl's Block in declaration order: (path, scalar kind, components).
BLOCK = [
    ("a", "f32", 1), ("m3", "f32", 9), ("v3", "f32", 3), ("w", "f32", 1), ("v2", "f32", 2),
    ("arr", "f32", 8), ("m2", "f32", 4), ("m42", "f32", 8), ("inner.dir", "f32", 3), ("inner.s", "f32", 1),
    ("k", "u32", 1), ("i", "i32", 1), ("u2", "u32", 2), ("m4", "f32", 16), ("v4i", "i32", 4),
]


def bits(kind, v):
    if kind == "f32":
        return struct.unpack("<I", struct.pack("<f", float(v)))[0]
    return int(v) & 0xFFFFFFFF


def flat(v):
    if isinstance(v, list):
        return [x for e in v for x in flat(e)]
    return [v]


def layout_probes():
    manifest = tomllib.loads((HERE / "kernels/layout_uniform.toml").read_text())
    params = {p["name"]: p["default"] for p in manifest["param"]}
    words = []
    for path, kind, n in BLOCK:
        values = flat(params[f"blk.{path}"])
        assert len(values) == n, (path, values)
        words += [bits(kind, v) for v in values]
    storage = tomllib.loads((HERE / "kernels/layout_storage.toml").read_text())
    data = next(r for r in storage["resource"] if r["name"] == "block")["data"]
    kinds = [kind for _, kind, n in BLOCK for _ in range(n)]
    assert len(data) == len(kinds)
    storage_words = [bits(k, v) for k, v in zip(kinds, data)]
    why = "each leaf's components in declaration order, matrices column after column, as the shader reads them"
    return [
        {"kernel": "layout_uniform", "set": {}, "output": "leaves", "words": words, "why": why},
        {"kernel": "layout_storage", "set": {}, "output": "leaves", "words": storage_words, "why": why},
    ]


def entry_name_probes():
    # fill_u32 writes 32 and arrayLength of the 4-u32 buffer; fill_f16 writes 16; the last word stays 0.
    return [{"kernel": "entry_names", "set": {}, "output": "words", "words": [32, 4, 16, 0],
             "why": "each pass ran its own entry point, found by the name the module gives it"}]


def render():
    out = ["# Written by expected.py from the WGSL and WebGPU specs; do not edit.",
           "# tests/conformance.rs runs each probe on every backend and compares the",
           "# output's 32-bit words exactly.", ""]
    for p in array_length_probes() + layout_probes() + entry_name_probes():
        sets = ", ".join(f"{k} = {v}" for k, v in p["set"].items())
        out += ["[[probe]]", f'kernel = "{p["kernel"]}"', f"set = {{ {sets} }}" if sets else "set = {}",
                f'output = "{p["output"]}"', f'why = "{p["why"]}"']
        out += ["words = [" + ", ".join(str(w) for w in p["words"]) + "]", ""]
    # Backend differences from the specs, named here so the suite shows them.
    out += ["# [[difference]] backend = \"...\", kernel = \"...\", reason = \"...\": none found."]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    text = render()
    target = HERE / "expected.toml"
    if "--check" in sys.argv[1:]:
        if not target.exists() or target.read_text() != text:
            print("expected.toml is not what expected.py writes: run python3 tests/conformance/expected.py")
            sys.exit(1)
        print("expected.toml matches expected.py")
    else:
        target.write_text(text)
