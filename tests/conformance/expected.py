#!/usr/bin/env python3
"""Expected values of vista's host-layer conformance probes, derived from
the WGSL and WebGPU specifications (never from vista, never blessed).

    python3 expected.py          # writes expected.toml and the probes' inputs/ beside this file
    python3 expected.py --check  # exits 1 if any of them is not what it would write

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
            "kernel": "array_length", "set": {"n": n}, "outputs": ["lengths"], "words": words,
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
        {"kernel": "layout_uniform", "set": {}, "outputs": ["leaves"], "words": words, "why": why},
        {"kernel": "layout_storage", "set": {}, "outputs": ["leaves"], "words": storage_words, "why": why},
    ]


def entry_name_probes():
    # fill_u32 writes 32 and arrayLength of the 4-u32 buffer; fill_f16 writes 16; the last word stays 0.
    return [{"kernel": "entry_names", "set": {}, "outputs": ["words"], "words": [32, 4, 16, 0],
             "why": "each pass ran its own entry point, found by the name the module gives it"}]


# WebGPU 23.2.6 (blend state): factor values for a colour component (rgb)
# and for the alpha component, given source S, destination D and constant C.
def factor(name, comp, S, D, C):
    alpha = comp == 3
    sat = 1.0 if alpha else min(S[3], 1.0 - D[3])
    return {
        "zero": 0.0, "one": 1.0,
        "src": S[comp], "one-minus-src": 1.0 - S[comp],
        "src-alpha": S[3], "one-minus-src-alpha": 1.0 - S[3],
        "dst": D[comp], "one-minus-dst": 1.0 - D[comp],
        "dst-alpha": D[3], "one-minus-dst-alpha": 1.0 - D[3],
        "src-alpha-saturated": sat,
        "constant": C[comp], "one-minus-constant": 1.0 - C[comp],
    }[name]


def blend(state, comp, S, D, C):
    sf, df, op = state
    s, d = S[comp] * factor(sf, comp, S, D, C), D[comp] * factor(df, comp, S, D, C)
    return {"add": s + d, "subtract": s - d, "reverse-subtract": d - s,
            "min": min(S[comp], D[comp]), "max": max(S[comp], D[comp])}[op]


def f16_bits_as_f32(v):
    """v stored in an rgba16float texel (round to nearest), read back as f32 bits."""
    h = struct.unpack("<e", struct.pack("<e", v))[0]
    return bits("f32", h)


def blend_probes():
    manifest = tomllib.loads((HERE / "kernels/blend.toml").read_text())
    shader = (HERE / "shaders/blend.wgsl").read_text()
    src = [float(x) for x in shader.split("const SRC = vec4<f32>(")[1].split(")")[0].split(",")]
    outputs, words = [], []
    for p in manifest["pass"]:
        for t in p["targets"]:
            D, C = t["clear"], t["blend"].get("constant", [0.0, 0.0, 0.0, 0.0])
            out = [blend(t["blend"]["color"] if c < 3 else t["blend"]["alpha"], c, src, D, C) for c in range(4)]
            outputs.append(t["resource"])
            words += [f16_bits_as_f32(v) for v in out]
    return [{"kernel": "blend", "set": {}, "outputs": outputs, "words": words,
             "why": "WebGPU's blend equation per target: result = op(src * srcFactor, dst * dstFactor), "
                    "stored in rgba16float; four words (r, g, b, a) per target"}]


# The vertices of kernels/vertex_fetch.toml's buffer: one tuple per attribute, raw values as stored.
VERTICES = [
    {"u8": (0, 255), "i8": (-128, 127), "un8": (0, 255, 255, 0), "sn8": (-127, 127, 0, -128),
     "u16": (0, 65535), "i16": (-32768, 32767), "un16": (0, 65535), "h4": (0.5, -2.0, 1024.0, 2.0 ** -10),
     "f3": (1.5, -0.25, 300000.0), "packed": (1023, 0, 1023, 3)},
    {"u8": (7, 200), "i8": (-1, 64), "un8": (255, 0, 0, 255), "sn8": (127, -127, -128, 0),
     "u16": (1234, 4321), "i16": (-1, 1000), "un16": (65535, 0), "h4": (-0.5, 65504.0, 0.0, 1.0),
     "f3": (-7.0, 0.125, 2.0 ** -20), "packed": (0, 1023, 0, 0)},
    {"u8": (128, 1), "i8": (5, -5), "un8": (0, 0, 255, 255), "sn8": (0, 0, 127, -127),
     "u16": (40000, 2), "i16": (-300, 300), "un16": (0, 0), "h4": (3.0, -6.25, 0.75, -1.0),
     "f3": (0.0, -1.0, 1.0), "packed": (1023, 1023, 0, 3)},
]
INSTANCES = [(100, 200), (101, 201)]
POINT_WORDS = 40


def pack_vertex(v):
    r, g, b, a = v["packed"]
    return (struct.pack("<2B", *v["u8"]) + struct.pack("<2b", *v["i8"]) + struct.pack("<4B", *v["un8"])
            + struct.pack("<4b", *v["sn8"]) + struct.pack("<2H", *v["u16"]) + struct.pack("<2h", *v["i16"])
            + struct.pack("<2H", *v["un16"]) + struct.pack("<4e", *v["h4"]) + struct.pack("<3f", *v["f3"])
            + struct.pack("<I", r | g << 10 | b << 20 | a << 30))


def vertex_inputs():
    """The two .bin files the vertex_fetch probe reads, as bytes."""
    vertices = b"".join(pack_vertex(v) for v in VERTICES)
    assert len(vertices) == 48 * len(VERTICES)
    return {"inputs/vertices.bin": vertices,
            "inputs/instances.bin": b"".join(struct.pack("<2I", *i) for i in INSTANCES)}


def vertex_probes():
    # WebGPU 23.2.5 (vertex formats): unorm c / (2^n - 1); snorm max(c / (2^(n-1) - 1), -1); integers as
    # stored; float16 widened exactly; unorm10-10-10-2 r in bits 0-9, g 10-19, b 20-29, a 30-31.
    words = []
    for i, inst in enumerate(INSTANCES):
        for vi, v in enumerate(VERTICES):
            f = lambda x: bits("f32", x)
            w = [vi, i]
            w += list(v["u8"]) + [bits("i32", x) for x in v["i8"]]
            w += [f(c / 255) for c in v["un8"]] + [f(max(c / 127, -1.0)) for c in v["sn8"]]
            w += list(v["u16"]) + [bits("i32", x) for x in v["i16"]] + [f(c / 65535) for c in v["un16"]]
            w += [f(x) for x in v["h4"]] + [f(x) for x in v["f3"]]
            r, g, b, a = v["packed"]
            w += [f(r / 1023), f(g / 1023), f(b / 1023), f(a / 3)]
            w += list(inst)
            w += [len(INSTANCES) * 2]  # arrayLength of the 16-byte instance buffer as array<u32>
            words += w + [0] * (POINT_WORDS - len(w))
    return [{"kernel": "vertex_fetch", "set": {}, "outputs": ["fetched"], "words": words,
             "why": "per point: vertex and instance index, then each attribute converted as WebGPU's vertex "
                    "formats say (normalized values chosen at 0 and the extremes, so exact), then the "
                    "per-instance attribute"}]


def texture_query_probes():
    # WGSL 17.7 (texture built-ins): textureDimensions(t, level) = max(1, size >> level) per axis (the
    # array layers and cube faces not counted); textureNumLevels = the view's mip levels;
    # textureNumLayers = the array layers. A storage view of level L has the extent of level L.
    manifest = tomllib.loads((HERE / "kernels/texture_queries.toml").read_text())
    res = {r["name"]: r for r in manifest["resource"]}
    dim = lambda name, level: [max(1, n >> level) for n in res[name]["size"]]
    levels = lambda name: res[name].get("mip_levels", 1)
    w = dim("line", 0) + [levels("line")]
    w += dim("plane", 0) + dim("plane", 2) + dim("plane", 3) + [levels("plane")]
    w += dim("layers", 0)[:2] + [res["layers"]["size"][2], levels("layers")]
    w += dim("volume", 0) + dim("volume", 1) + [levels("volume")]
    w += dim("sky", 0) * 2 + [levels("sky")]
    w += dim("mips", 2) + [0xD1A]
    return [{"kernel": "texture_queries", "set": {}, "outputs": ["shape"], "words": w,
             "why": "size >> level per axis (at least 1), mip levels and array layers as declared"}]


# WebGPU 23.3 / Vulkan 16.x (texel filtering and addressing), for a W x H texture.
def wrap(i, n, mode):
    if mode == "clamp-to-edge":
        return min(max(i, 0), n - 1)
    if mode == "repeat":
        return i % n
    mirror = lambda k: k if k >= 0 else -(1 + k)
    return (n - 1) - mirror((i % (2 * n)) - n)


def sample(texel, size, uv, linear, mode):
    import math
    if not linear:
        x, y = (wrap(math.floor(c * n), n, mode) for c, n in zip(uv, size))
        return texel(x, y)
    (x0, a), (y0, b) = ((math.floor(c * n - 0.5), c * n - 0.5 - math.floor(c * n - 0.5)) for c, n in zip(uv, size))
    t = lambda i, j: texel(wrap(i, size[0], mode), wrap(j, size[1], mode))
    return [(1 - a) * (1 - b) * p + a * (1 - b) * q + (1 - a) * b * r + a * b * s
            for p, q, r, s in zip(t(x0, y0), t(x0 + 1, y0), t(x0, y0 + 1), t(x0 + 1, y0 + 1))]


def sampling_probes():
    shader = (HERE / "shaders/sampling.wgsl").read_text()
    body = shader.split("const COORDS = array<vec2<f32>, 8>(")[1].split(");")[0]
    coords = [[float(v) / 64 for v in pair.split(",")] for pair in body.replace("vec2<f32>(", "").split("),") if pair.strip()]
    coords = [[c for c in pair if True] for pair in coords]
    assert len(coords) == 8, coords
    texel = lambda x, y: [x / 8 + y / 2, float(x), float(y), 1.0]
    words = []
    for uv in coords:
        for linear in (False, True):
            for mode in ("clamp-to-edge", "repeat", "mirror-repeat"):
                words += [bits("f32", v) for v in sample(texel, (4, 4), uv, linear, mode)]
    return [{"kernel": "sampling", "set": {}, "outputs": ["samples"], "words": words,
             "why": "per coordinate: nearest then linear, each clamp-to-edge, repeat, mirror-repeat; "
                    "four words (r, g, b, a) per sample, bilinear in f64 from the texel centres"}]


# WebGPU 26.1 / WGSL 17.7.6 (texel formats): what textureStore writes into each storable format.
def stored(fmt, v):
    import math
    rne = lambda x: math.floor(x + 0.5) if x - math.floor(x) != 0.5 else 2 * round(x / 2)
    channels = {"r32": 1, "rg32": 2}.get(fmt.rstrip("floatuinsi"), 4)
    if fmt.endswith("unorm"):
        out = [rne(min(max(x, 0.0), 1.0) * 255) / 255 for x in v]
    elif fmt.endswith("snorm"):
        out = [max(rne(min(max(x, -1.0), 1.0) * 127) / 127, -1.0) for x in v]
    elif fmt == "rgba16float":
        out = [struct.unpack("<e", struct.pack("<e", x))[0] for x in v]
    else:
        out = [float(x) for x in v]  # 32-bit floats and integers as stored, read back as f32
    return out[:channels] + [0.0, 0.0, 1.0][channels - 1:] if channels < 4 else out


def format_probes():
    shader = (HERE / "shaders/formats.wgsl").read_text()
    manifest = tomllib.loads((HERE / "kernels/formats.toml").read_text())
    words = []
    for out in manifest["output"]:
        fmt = out["resource"]
        line = next(l for l in shader.splitlines() if l.strip().startswith(f"textureStore(t_{fmt},"))
        args = line.split("vec4<")[1].split(">(")[1].rstrip(");").split(",")
        v = [float(a.strip().rstrip("u")) for a in args]
        words += [bits("f32", x) for x in stored(fmt, v)]
    return [{"kernel": "formats", "set": {}, "outputs": [o["resource"] for o in manifest["output"]], "words": words,
             "why": "each format's texel as textureStore converts the written value, read back as f32 RGBA "
                    "(normalized values rounded to the nearest step, missing channels 0, 0, 1)"}]


def workgroup_zero_probes():
    # WGSL (variable declarations, workgroup address space): a workgroup variable is zero-initialized when its
    # workgroup starts, so every word a workgroup reads before writing is 0 (f32 +0.0 has bits 0); the
    # atomic, zero at the start, counts the 64 lanes that then add one each.
    lanes, groups = 64, 8
    words = []
    for g in range(groups):
        words += [0] * lanes + [0] * 12 + [0] + [0] + [lanes, g]
    return [{"kernel": "workgroup_zero", "set": {}, "outputs": ["seen"], "words": words,
             "why": "per workgroup (80 words): the 64-word array, the struct Cell (vec3, i32, mat2x2, array<u32, 4>), "
                    "the f32 and the atomic as read before any write, all zero; then the atomic after 64 adds "
                    "and the workgroup id"}]


# WebGPU (primitive assembly; rasterization, polygon coverage) for the 8 x 8 targets of
# kernels/indices.toml: every corner lies on whole pixels, so a pixel centre (x + 0.5, y + 0.5) is either
# strictly inside or outside each triangle, or on an edge that two triangles of the draw share from opposite
# sides (a quad's diagonal), where the tie-break rule gives it to exactly one of them: covered either way.
def edge(a, b, p):
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])


def covered(triangles, p):
    on_edges = []
    for tri in triangles:
        e = [edge(tri[i], tri[(i + 1) % 3], p) for i in range(3)]
        if all(v > 0 for v in e) or all(v < 0 for v in e):
            return True
        if all(v >= 0 for v in e) or all(v <= 0 for v in e):
            if sum(1 for v in e if v == 0) == 1 and abs(sum(e)) > 0:  # on one edge of a non-degenerate triangle
                i = next(i for i in range(3) if e[i] == 0)
                on_edges.append(frozenset([tri[i], tri[(i + 1) % 3]]))
    for seg in set(on_edges):
        assert on_edges.count(seg) == 2, f"pixel centre {p} lies on an unshared edge {sorted(seg)}: ambiguous"
    return bool(on_edges)


def index_probes():
    manifest = tomllib.loads((HERE / "kernels/indices.toml").read_text())
    data = {r["name"]: r["data"] for r in manifest["resource"] if "data" in r}
    outputs, words = [], []
    for p in manifest["pass"]:
        fmt, tag = p["indices"]["format"], p["set"]["tag"]
        restart = {"uint16": 0xFFFF, "uint32": 0xFFFFFFFF}[fmt]
        indices = data[p["indices"]["resource"]][:p["count"]]
        assert all(0 <= i <= restart for i in indices)
        # A vertex's corner as shaders/indices.wgsl places it: from the index's low byte if its high bits
        # are the pass's tag, else (0, 8).
        corner = lambda i: ((i & 0xF, (i >> 4) & 0xF) if i >> 8 == tag else (0, 8))
        if p["topology"] == "triangle-strip":
            strips, run = [], []
            for i in indices + [restart]:  # the strip restarts at the format's largest value
                if i == restart:
                    strips.append(run)
                    run = []
                else:
                    run.append(corner(i))
            triangles = [s[k:k + 3] for s in strips for k in range(len(s) - 2)]
        else:
            triangles = [[corner(i) for i in indices[k:k + 3]] for k in range(0, len(indices) - 2, 3)]
        target = p["targets"][0]["resource"]
        outputs.append(target)
        for y in range(8):
            for x in range(8):
                v = 1.0 if covered(triangles, (x + 0.5, y + 0.5)) else 0.0
                words += [bits("f32", c) for c in (v, 0.0, 0.0, 1.0)]
    return [{"kernel": "indices", "set": {}, "outputs": outputs, "words": words,
             "why": "per target, rows top to bottom, r32uint read back as f32 (r, 0, 0, 1): 1 where a triangle "
                    "covers the pixel centre; strips restart at 0xFFFF (uint16) and 0xFFFFFFFF (uint32), "
                    "0xFFFF in a uint32 strip is an ordinary index"}]


# WebGPU (depth test): a fragment passes if compare(its depth, the stored depth) holds, then (with
# depth writes) stores its depth. kernels/depth_compare.toml clears to 0.5; shaders/depth_compare.wgsl writes
# frag_depth 0.25, 0.5, 0.75 at pixels 0, 1, 2 (exact in f32 and depth32float).
COMPARE = {
    "never": lambda f, s: False, "less": lambda f, s: f < s, "equal": lambda f, s: f == s,
    "less-equal": lambda f, s: f <= s, "greater": lambda f, s: f > s, "not-equal": lambda f, s: f != s,
    "greater-equal": lambda f, s: f >= s, "always": lambda f, s: True,
}


def depth_probes():
    manifest = tomllib.loads((HERE / "kernels/depth_compare.toml").read_text())
    colors, depths = {}, {}
    for p in manifest["pass"]:
        d, target = p["depth"], p["targets"][0]["resource"]
        passed = [COMPARE[d["compare"]](f, d["clear"]) for f in (0.25, 0.5, 0.75)]
        colors[target] = [1.0 if ok else 0.0 for ok in passed]
        depths[d["resource"]] = [f if ok and d["write"] else d["clear"] for f, ok in zip((0.25, 0.5, 0.75), passed)]
    outputs = [o["resource"] for o in manifest["output"]]
    words = []
    for name in outputs:
        for v in {**colors, **depths}[name]:
            words += [bits("f32", c) for c in (v, 0.0, 0.0, 1.0)]
    return [{"kernel": "depth_compare", "set": {}, "outputs": outputs, "words": words,
             "why": "per compare function, the r32uint colour (1 where the fragment passed) then the depth32float "
                    "buffer, each read back as f32 (r, 0, 0, 1) for pixels at fragment depth 0.25, 0.5, 0.75 "
                    "against a clear of 0.5"}]


# Exact rounding of a rational to a binary float of `mantissa` stored bits and exponents down to `emin`
# (subnormals below), to nearest even or toward zero.
def round_float(q, mantissa, emin, toward_zero=False):
    from fractions import Fraction
    q = Fraction(q)
    if q == 0:
        return q
    sign, a = (-1 if q < 0 else 1), abs(q)
    e = a.numerator.bit_length() - a.denominator.bit_length()
    e += 1 if a >= Fraction(2) ** (e + 1) else 0
    e -= 1 if a < Fraction(2) ** e else 0
    step = Fraction(2) ** (max(e, emin) - mantissa)
    n, rest = divmod(a / step, 1)
    if not toward_zero and (rest > Fraction(1, 2) or (rest == Fraction(1, 2) and n % 2 == 1)):
        n += 1
    return sign * n * step


def f32_of(q):
    return round_float(q, 23, -126)


def f32_bits_of(q):
    return bits("f32", float(f32_of(q)))


def render_format_probes():
    # WebGPU (texture formats) with Vulkan's conversions (fixed-point data conversions: unorm
    # clamps to [0, 1] and rounds x * (2^n - 1) to the nearest integer; 16-bit and packed unsigned floats
    # round to the nearest representable value). Read back as vista reads a texture: f32 RGBA, a unorm
    # channel k / (2^n - 1) divided in f32, missing channels 0, 0, 1, bgra8unorm's channels back in
    # r, g, b, a order.
    import re
    from fractions import Fraction
    shader = (HERE / "shaders/render_formats.wgsl").read_text()
    consts = {name.lower(): (kind, [Fraction(v.strip().rstrip("u")) for v in args.split(",")])
              for name, kind, args in re.findall(r"const (\w+) = vec4<(f32|u32|i32)>\(([^)]*)\);", shader)}

    def unorm(v, n):
        top = 2 ** n - 1
        x = min(max(v, Fraction(0)), Fraction(1)) * top
        k = round(x)
        assert abs(x - k) <= Fraction(1, 4), f"{float(v)} scales to {float(x)}: too near a rounding tie"
        return f32_of(Fraction(k, top))

    def narrow(v, mantissa):
        near, zero = round_float(v, mantissa, -14), round_float(v, mantissa, -14, toward_zero=True)
        assert near == zero, f"{float(v)}: rounding to nearest and toward zero differ"
        return near

    probes = []
    for kernel in ("render_formats", "render_packed"):
        manifest = tomllib.loads((HERE / f"kernels/{kernel}.toml").read_text())
        outputs, words = [o["resource"] for o in manifest["output"]], []
        for fmt in outputs:
            kind, v = consts[fmt]
            v = [f32_of(x) for x in v] if kind == "f32" else v
            if fmt == "rgb10a2unorm":
                out = [unorm(x, 10) for x in v[:3]] + [unorm(v[3], 2)]
            elif fmt == "rg11b10ufloat":
                assert all(x >= 0 for x in v)
                out = [narrow(v[0], 6), narrow(v[1], 6), narrow(v[2], 5)]
            elif "8unorm" in fmt:
                out = [unorm(x, 8) for x in v]
            elif "16float" in fmt:
                out = [narrow(x, 10) for x in v]
            else:
                out = v  # 32-bit floats and every integer format: stored as written
                assert all(f32_of(x) == x for x in out), f"{fmt}: pick values exact in f32 (vista reads back f32)"
            n = 3 if fmt == "rg11b10ufloat" else {"r": 1, "rg": 2}.get(re.match(r"[a-z]+", fmt).group(), 4)
            out = out[:n] + [Fraction(0), Fraction(0), Fraction(1)][n - 1:] if n < 4 else out[:4]
            words += [f32_bits_of(x) for x in out]
        probes.append({"kernel": kernel, "set": {}, "outputs": outputs, "words": words,
                       "why": "each target's texel as the attachment format converts the fragment's value, read back "
                              "as f32 RGBA (unorm rounded to the nearest step, values chosen at least 0.25 of a step "
                              "from a tie; float16 and 11/10-bit floats where nearest and toward-zero rounding "
                              "agree; missing channels 0, 0, 1)"})
    return probes


# shaders/struct_arrays.wgsl's Item: (member, leaf kind, (align, size) by WGSL 13.4, components).
ITEM = [("p", "f32", vec(3), 3), ("id", "u32", scalar(), 1), ("uv", "f32", vec(2), 2), ("k", "i32", scalar(), 1),
        ("m", "f32", mat(2, 2), 4), ("tags", "u32", array(scalar(), 3), 3), ("q", "i32", vec(4), 4)]
FILE_ITEMS = [
    [0.375, -0.625, 12.5, 301, -1.25, 1.75, -66, 0.5, 0.25, -0.5, -0.25, 57, 58, 59, 1000, -2000, 3000, -4000],
    [-13.5, 14.25, -15.0, 302, 16.5, -17.75, 77, -18.0, 19.0, -20.0, 21.0, 67, 68, 69, -5000, 6000, -7000, 8000],
]


def item_offsets():
    """Each member's byte offset, the Item's stride and size by WGSL 13.4."""
    offsets, offset = [], 0
    for _, _, (a, s), _ in ITEM:
        offset = round_up(a, offset)
        offsets.append(offset)
        offset += s
    align, size = struct_of([m[2] for m in ITEM])
    return offsets, stride((align, size)), align


def item_inputs():
    """inputs/items.bin: FILE_ITEMS laid out at their offsets, padding bytes 0xEE."""
    offsets, step, _ = item_offsets()
    out = b""
    for values in FILE_ITEMS:
        el, at = bytearray(b"\xEE" * step), 0
        for (_, kind, _, n), off in zip(ITEM, offsets):
            for c in range(n):
                el[off + 4 * c:off + 4 * c + 4] = struct.pack("<I", bits(kind, values[at]))
                at += 1
        out += bytes(el)
    return {"inputs/items.bin": out}


def struct_array_probes():
    offsets, step, align = item_offsets()
    assert (offsets, step, align) == ([0, 12, 16, 24, 32, 48, 64], 80, 16), (offsets, step, align)
    manifest = tomllib.loads((HERE / "kernels/struct_arrays.toml").read_text())
    data = {r["name"]: r.get("data") for r in manifest["resource"]}
    kinds = [kind for _, kind, _, n in ITEM for _ in range(n)]
    per = len(kinds)
    flat_file = [v for it in FILE_ITEMS for v in it]
    words, lengths = [], []
    for values in (data["from_data"], flat_file, data["tail"]):
        assert len(values) % per == 0
        words += [bits(k, v) for k, v in zip(kinds * (len(values) // per), values)]
        lengths.append(len(values) // per)
    # tail.count: the header before the array (offset 0, the array at roundUp(16, 4) = 16) is never fed: 0.
    words += lengths + [0, 0x57AC]
    return [{"kernel": "struct_arrays", "set": {}, "outputs": ["leaves"], "words": words,
             "why": "every leaf of every Item (stride 80: vec3 at 0, u32 at 12, vec2 at 16, i32 at 24, mat2x2 at 32, "
                    "array<u32, 3> at 48, vec4<i32> at 64) from data, from the file and behind the header; then the "
                    "three arrayLengths, the header's zero count and the marker"}]


def view_probes():
    # WebGPU (texture views): a view of base level k and one level sees the texture's level k as its level
    # 0, with that level's size (max(1, size >> k)) and one level; a render target or storage view of one
    # level (and layer) writes only that subresource. kernels/views.toml writes texel (x, y) of level l of
    # pyr as (10 + l, x, y, 1), of level l of layer a of arr as (100 + 10a + l, x, y, 1); nearest sampling
    # at level l takes texel floor(uv * size of level l).
    import math
    manifest = tomllib.loads((HERE / "kernels/views.toml").read_text())
    res = {r["name"]: r for r in manifest["resource"]}
    tags = {}
    for p in manifest["pass"]:
        target = p["bind"]["level_out"] if "bind" in p and "level_out" in p["bind"] else None
        target = target or (p["targets"][0]["resource"] if "targets" in p else None)
        if target:
            name, _, rest = target.partition("@")
            level, _, layer = rest.partition("@layer")
            tags[(name, int(level or 0), int(layer or 0))] = p["set"]["tag"]
    size = lambda name, level: [max(1, n >> level) for n in res[name]["size"][:2]]

    def load(name, level, x, y, layer=0):
        w, h = size(name, level)
        assert 0 <= x < w and 0 <= y < h
        return [tags[(name, level, layer)], x, y, 1]

    def nearest(name, level, uv, layer=0):
        return load(name, level, *(math.floor(c * n) for c, n in zip(uv, size(name, level))), layer)

    levels = lambda name: res[name].get("mip_levels", 1)
    rows = []
    for level in range(levels("pyr")):
        last = size("pyr", level)[0] - 1
        rows += [load("pyr", level, last, 0), load("pyr", level, 0, last)]
    rows += [load("pyr", 1, 2, 3), load("pyr", 2, 1, 1)]  # through views of levels 1 and 2, at their level 0
    rows += [nearest("pyr", 2, (0.75, 0.25))] * 2 + [nearest("pyr", 1, (0.3, 0.8))] * 2
    rows += [size("pyr", 0) + [levels("pyr"), 1], size("pyr", 1) + [1, 1], size("pyr", 2) + [1, 1]]
    layers = res["arr"]["size"][2]
    for layer in range(layers):
        rows += [load("arr", 0, 3, 3, layer), load("arr", 1, 1, 1, layer), load("arr", 1, 1, 0, layer)]
    rows += [nearest("arr", 1, (0.6, 0.1), 2)] * 2
    rows += [size("arr", 0) + [levels("arr"), layers], size("arr", 1) + [1, layers]]
    words = [bits("f32", v) for row in rows for v in row]
    return [{"kernel": "views", "set": {}, "outputs": ["seen"], "words": words,
             "why": "four words per read: texels (tag, x, y, 1) loaded and nearest-sampled through the whole "
                    "texture and through one-level views, and (width, height, levels, layers) of each view"}]


def out_of_bounds_probes():
    # WGSL (out-of-bounds access; textureLoad, textureStore): the shader flags each
    # out-of-bounds result 1 when it is one the spec allows (see shaders/out_of_bounds.wgsl), so every flag
    # is 1 whatever a conforming backend chose; the words of the buffer beside the stored-to one are
    # unchanged, and each arrayLength is the declared length.
    manifest = tomllib.loads((HERE / "kernels/out_of_bounds.toml").read_text())
    data = {r["name"]: r.get("data") for r in manifest["resource"]}
    n = len(data["idx"])
    # Past the end of every array they index (5, 4 and 2 elements), as u32 and as i32 (2^31 and up: negative).
    assert all(i >= max(len(data["data"]), len(data["victim"])) for i in data["idx"])
    words = [1] * (5 * n)                  # loads: data (u32 and i32 index), private, workgroup, uniform
    words += [1] * (2 * len(data["victim"]))  # the stored-to storage and private arrays afterwards
    words += data["guard"] + [len(data["data"]), len(data["victim"])]
    texels = 2 * 2
    words += [1] * texels + [1] * (len(data["coords"]) // 2 + len(data["levels"])) + [0x00B5]
    return [{"kernel": "out_of_bounds", "set": {}, "outputs": ["flags"], "words": words,
             "why": "1 per out-of-bounds result that WGSL allows (zero, bytes of the bound buffer or variable, "
                    "(0, 0, 0, x) for vectors; a store dropped or kept inside its buffer; a texel, (0, 0, 0, 0) or "
                    "(0, 0, 0, 1) for textureLoad), the guard buffer's own words, arrayLength of data and victim, "
                    "texture flags, marker"}]


def draw_offset_probes():
    # WebGPU draw(vertexCount, instanceCount, firstVertex, firstInstance) and drawIndexed(indexCount,
    # instanceCount, firstIndex, baseVertex, firstInstance); WGSL: vertex_index is the vertex's index
    # (for an indexed draw, the index buffer's entry plus baseVertex), instance_index counts from
    # firstInstance, and attributes are fetched at those indices.
    seen = [[0, 0, 0, 0] for _ in range(64)]
    def point(v, i):
        seen[i * 8 + v] = [v, i, 100 + v, 1000 + i]
    for i in (5, 6):                       # first_instance 5, instances 2
        for v in (3, 4):                   # first_vertex 3, count 2
            point(v, i)
    for index in (0, 2):                   # indices [0, 2], base_vertex 5, first_instance 1
        point(index + 5, 1)
    for index in (4, 6):                   # indices [4, 6], base_vertex -3, first_instance 7
        point(index - 3, 7)
    return [{"kernel": "draw_offsets", "set": {}, "outputs": ["seen"], "words": [w for p in seen for w in p],
             "why": "per pixel (vertex_index, instance_index) of an 8 x 8 target: the vertex and instance index "
                    "and the per-vertex and per-instance attributes fetched there, zeros where no point fell"}]


def depth_as_float_probes():
    # WebGPU: a depth32float texture binds as sampleType "unfilterable-float"; only .r of the loaded
    # value is the depth, so the shader stores (d, 0, 0, 1). The triangle's z = 0.25 at w = 1 is the
    # fragment depth (viewport depth range [0, 1]), exact in f32.
    words = []
    for _ in range(8 * 8):
        words += [bits("f32", 0.25), bits("f32", 0.0), bits("f32", 0.0), bits("f32", 1.0)]
    return [{"kernel": "depth_as_float", "set": {}, "outputs": ["out"], "words": words,
             "why": "per texel of 8 x 8: the depth 0.25 a full-screen draw wrote, loaded through texture_2d<f32>"}]


PROBES = [array_length_probes, layout_probes, entry_name_probes, blend_probes, vertex_probes, texture_query_probes,
          sampling_probes, format_probes, workgroup_zero_probes,
          index_probes, depth_probes, render_format_probes,
          struct_array_probes, view_probes, out_of_bounds_probes, draw_offset_probes,
          depth_as_float_probes]


def render():
    out = ["# Written by expected.py from the WGSL and WebGPU specs; do not edit.",
           "# tests/conformance.rs runs each probe on every backend and compares the",
           "# output's 32-bit words exactly.", ""]
    for p in [p for probes in PROBES for p in probes()]:
        sets = ", ".join(f"{k} = {v}" for k, v in p["set"].items())
        out += ["[[probe]]", f'kernel = "{p["kernel"]}"', f"set = {{ {sets} }}" if sets else "set = {}",
                "outputs = [" + ", ".join(f'"{o}"' for o in p["outputs"]) + "]", f'why = "{p["why"]}"']
        out += ["words = [" + ", ".join(str(w) for w in p["words"]) + "]", ""]
    # Backend differences from the specs, named here so the suite shows them.
    out += ["# [[difference]] backend = \"...\", kernel = \"...\", reason = \"...\": none found."]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    files = {"expected.toml": render().encode(), **vertex_inputs(), **item_inputs()}
    if "--check" in sys.argv[1:]:
        stale = [name for name, data in files.items()
                 if not (HERE / name).exists() or (HERE / name).read_bytes() != data]
        if stale:
            print(f"{', '.join(stale)}: not what expected.py writes: run python3 tests/conformance/expected.py")
            sys.exit(1)
        print("expected.toml and the probes' inputs match expected.py")
    else:
        for name, data in files.items():
            (HERE / name).write_bytes(data)
