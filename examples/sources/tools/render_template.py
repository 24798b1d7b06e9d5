#!/usr/bin/env python3
"""The project's own template renderer: what its host runs before handing
WGSL to the GPU, and what vista runs through `[source] command`.

    render_template.py TEMPLATE PARAMS.json OUT

A template holds `{{ name }}` (a value of the context, `t.weight` a field
of a loop variable) and `{% for t in name %} ... {% endfor %}` (not nested).
The context is PARAMS.json plus `taps`: the normalised Gaussian weights
exp(-i^2 / (2 sigma^2)) for i in -radius..radius, so the kernel is unrolled
with its weights as literals.
"""
import json
import math
import re
import sys

FOR = re.compile(r"\{%\s*for\s+(\w+)\s+in\s+(\w+)\s*%\}(.*?)\{%\s*endfor\s*%\}", re.S)
VALUE = re.compile(r"\{\{\s*([\w.]+)\s*\}\}")


def lookup(context, name):
    value = context
    for part in name.split("."):
        if part not in value:
            raise SystemExit(f"render_template: {name} is not in the context (known: {', '.join(sorted(context))})")
        value = value[part]
    return value


def literal(value):
    # repr keeps every digit of a float; WGSL reads it as an abstract float.
    return repr(value) if isinstance(value, float) else str(value)


def render(text, context):
    def loop(m):
        var, seq, body = m.group(1), m.group(2), m.group(3)
        return "".join(render(body, {**context, var: item}) for item in lookup(context, seq))

    text = FOR.sub(loop, text)
    return VALUE.sub(lambda m: literal(lookup(context, m.group(1))), text)


def main():
    if len(sys.argv) != 4:
        raise SystemExit("usage: render_template.py TEMPLATE PARAMS.json OUT")
    template, params, out = sys.argv[1:]
    with open(params) as f:
        context = json.load(f)
    radius, sigma = int(context["radius"]), float(context["sigma"])
    if radius < 1 or sigma <= 0:
        raise SystemExit(f"render_template: radius {radius} and sigma {sigma} must be positive")
    raw = [math.exp(-i * i / (2 * sigma * sigma)) for i in range(-radius, radius + 1)]
    total = sum(raw)
    context["taps"] = [{"offset": i - radius, "weight": w / total} for i, w in enumerate(raw)]
    with open(template) as f:
        text = render(f.read(), context)
    with open(out, "w") as f:
        f.write(text)


main()
