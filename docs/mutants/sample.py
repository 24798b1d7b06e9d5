#!/usr/bin/env python3
"""An independent mutation sample, judged by the goldens alone.

Draws N single-token mutants uniformly over every mutable token of the
project's WGSL (shaders/*.wgsl and shaders/lib/*.wgsl; not shaders/test),
with its own operators and its own random generator, so the sample does
not share `vista mutate`'s choices. Each mutant is applied to a copy of the
project and judged by `vista check --changed` there: exit 1 (a case fails)
kills it, exit 0 lets it survive; a mutant that does not compose (exit 2)
is stillborn and replaced by another draw. Prints one line per mutant and
the score; survivors are then read by hand to tell equivalent ones apart.

    python3 docs/mutants/sample.py VISTA_BINARY SEED N > out.txt
"""

import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

SWAPS = {
    "+": "-", "-": "+", "*": "/", "/": "*",
    "<": "<=", "<=": "<", ">": ">=", ">=": ">", "==": "!=", "!=": "==",
    "&&": "||", "||": "&&",
    "min": "max", "max": "min", "floor": "ceil", "ceil": "floor",
    "sin": "cos", "cos": "sin", "exp": "exp2", "log": "log2",
    ".x": ".y", ".y": ".z", ".z": ".x",
}
TOKEN = re.compile(
    r"(?P<num>(?<![\w.])\d+\.\d*(?:e[-+]?\d+)?f?|(?<![\w.])\d+(?:e[-+]?\d+)?[uif]?(?![\w.]))"
    r"|(?P<op>&&|\|\||<=|>=|==|!=|(?<![-+*/=<>!&|])[-+*/<>](?![-+*/=<>&|]))"
    r"|(?P<fn>\b(?:min|max|floor|ceil|sin|cos|exp|log)\b(?=\())"
    r"|(?P<swz>\.[xyz]\b)"
)


def code_lines(text):
    """(line index, code part) of lines that hold code, not declarations."""
    for i, line in enumerate(text.split("\n")):
        code = line.split("//")[0]
        s = code.strip()
        if not s or s.startswith("#") or s.startswith("@") or s.startswith("struct"):
            continue
        # Struct fields and bindings: `name: type,` lines carry no behaviour.
        if re.match(r"^\w+\s*:\s*[\w<>, ]+,?$", s):
            continue
        yield i, code


def mutation(kind, tok):
    if kind == "num":
        if tok.endswith("u") or tok.endswith("i") or re.fullmatch(r"\d+", tok):
            digits = tok.rstrip("ui")
            return str(int(digits) + 1) + tok[len(digits):]
        v = float(tok.rstrip("f"))
        return repr(v * 1.5 if v != 0.0 else 1.0)
    return SWAPS[tok]


def sites(root):
    out = []
    for d in ["shaders", "shaders/lib"]:
        for name in sorted(os.listdir(os.path.join(root, d))):
            if not name.endswith(".wgsl"):
                continue
            rel = os.path.join(d, name)
            text = open(os.path.join(root, rel)).read()
            for i, code in code_lines(text):
                for m in TOKEN.finditer(code):
                    kind = m.lastgroup
                    # `vec3<f32>` is a type, not a comparison: comparisons
                    # are written with spaces around them.
                    if m.group() in ("<", ">", "<=", ">=") and not code[m.start() - 1:m.start()].isspace():
                        continue
                    out.append((rel, i, m.start(), m.group(), kind))
    return out


def main():
    vista, seed, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    src = os.getcwd()
    rng = random.Random(seed)
    all_sites = sites(src)
    print(f"# seed {seed}: {len(all_sites)} mutable tokens", flush=True)
    work = tempfile.mkdtemp(prefix="vista-sample-")
    for d in ["shaders", "kernels", "golden"]:
        shutil.copytree(os.path.join(src, d), os.path.join(work, d))
    shutil.copy(os.path.join(src, "vista.toml"), work)
    killed = survived = stillborn = 0
    while killed + survived < n:
        rel, line, col, tok, kind = rng.choice(all_sites)
        path = os.path.join(work, rel)
        original = open(path).read()
        lines = original.split("\n")
        new_tok = mutation(kind, tok)
        lines[line] = lines[line][:col] + new_tok + lines[line][col + len(tok):]
        open(path, "w").write("\n".join(lines))
        try:
            r = subprocess.run(
                [vista, "check", "--root", work, "--changed", "--report-dir", os.path.join(work, "report")],
                capture_output=True, text=True, timeout=300)
            code = r.returncode
        except subprocess.TimeoutExpired:
            code = 124
        finally:
            open(path, "w").write(original)
        where = f"{rel}:{line + 1}: '{tok}' -> '{new_tok}'  | {original.split(chr(10))[line].strip()}"
        if code == 2:
            stillborn += 1
            continue
        if code == 0:
            survived += 1
            print(f"SURVIVED {where}", flush=True)
        else:
            killed += 1
            print(f"killed   {where}", flush=True)
    print(f"# seed {seed}: {killed} killed, {survived} survived of {n} ({100.0 * killed / n:.0f}%); "
          f"{stillborn} stillborn redrawn")
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
