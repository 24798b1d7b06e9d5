// vista report viewer. Pixel data comes from each case's view.js (a script:
// a page opened from file:// may neither fetch files nor read image pixels).
// HEAT_STOPS and LOG_FLOOR come before this script, from vista_image.
"use strict";

const onlyFailures = document.getElementById("failures-only");
const heatScale = document.getElementById("heat-scale");
const heatMax = document.getElementById("heat-max");
const viewers = new Map();
let active = null;

function applyFilter() {
  for (const d of document.querySelectorAll("details.case")) {
    d.hidden = onlyFailures.checked && !d.classList.contains("fail");
  }
}
onlyFailures.addEventListener("change", applyFilter);
applyFilter();

// A passing case identical to its golden ("plain") shows the command for
// its viewer once opened: made here, not written into each of a long
// suite's rows. Toggle does not bubble, so it is caught on the way down.
document.addEventListener("toggle", (e) => {
  const d = e.target;
  if (!d.open || !d.matches("details.case.plain") || d.querySelector(".viewer-cmd")) return;
  const p = document.createElement("p");
  p.className = "note viewer-cmd";
  const code = document.createElement("code");
  code.className = "cmd";
  code.textContent = `vista check --case '${d.querySelector("summary .id").textContent}' --full-report`;
  p.append("viewer: ", code);
  d.querySelector(".body").append(p);
}, true);

function decode(b64) {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  const out = new Uint16Array(bytes.length / 2);
  for (let i = 0; i < out.length; i++) out[i] = bytes[2 * i] | (bytes[2 * i + 1] << 8);
  return out;
}

function colormap(t) {
  t = Math.min(1, Math.max(0, t || 0));
  const seg = HEAT_STOPS.length - 1;
  const pos = t * seg;
  const i = Math.min(Math.floor(pos), seg - 1);
  const f = pos - i;
  const a = HEAT_STOPS[i], b = HEAT_STOPS[i + 1];
  return [0, 1, 2].map((c) => Math.round(255 * (a[c] + (b[c] - a[c]) * f)));
}

function logPos(d) {
  return d <= 0 ? 0 : Math.min(1, Math.max(0, Math.log10(d / LOG_FLOOR) / Math.log10(1 / LOG_FLOOR)));
}

function fmt(v) {
  return (v / 65535).toFixed(6);
}

class Viewer {
  constructor(el) {
    this.el = el;
    this.id = el.dataset.case;
    this.zoom = 2;
    this.showing = "actual";
    this.slider = false;
    this.split = 0.5;
  }

  request() {
    if (this.requested) return;
    this.requested = true;
    const s = document.createElement("script");
    s.src = this.el.dataset.src;
    s.onerror = () => {
      this.el.querySelector(".loading").textContent = "could not load " + s.src;
    };
    document.body.appendChild(s);
  }

  load(d) {
    this.w = d.w;
    this.h = d.h;
    // A tall image (stacked layers) comes as rows y0 .. y0 + h of full_h.
    this.y0 = d.y0 || 0;
    this.fullH = d.full_h || d.h;
    // No golden of this size: the render alone, at full size, to review.
    this.alone = d.expected === null;
    this.exp = this.alone ? null : decode(d.expected);
    this.act = decode(d.actual);
    this.firstBad = d.first_bad;
    this.build();
    this.draw();
    this.drawHeat();
  }

  build() {
    if (this.alone) {
      this.el.innerHTML =
        '<div class="vbar">zoom <button class="zoom-out" title="zoom out (-)">-</button> <span class="zv"></span> ' +
        '<button class="zoom-in" title="zoom in (+)">+</button>' +
        '<span class="readout">move the cursor over the image</span></div>' +
        '<div class="views"><div class="pane"><div class="label img-label"></div><div class="scroll"><canvas class="img"></canvas></div></div></div>';
    } else {
      this.buildCompare();
    }
    this.wire();
  }

  buildCompare() {
    this.el.innerHTML =
      '<div class="vbar"><button data-show="expected">expected</button><button data-show="actual">actual</button>' +
      '<button class="flip" title="key f">flip (f)</button><button class="slide">slider</button>' +
      ' zoom <button class="zoom-out" title="zoom out (-)">-</button> <span class="zv"></span> <button class="zoom-in" title="zoom in (+)">+</button>' +
      '<span class="readout">move the cursor over an image</span></div>' +
      '<div class="views"><div class="pane"><div class="label img-label"></div><div class="scroll"><canvas class="img"></canvas></div>' +
      '<input type="range" class="split" min="0" max="1" step="0.001" value="0.5" hidden ' +
      'title="where the image switches from expected (left) to actual (right)" aria-label="slider position"></div>' +
      '<div class="pane"><div class="label">heat map: max |actual - expected| over R, G, B</div><div class="scroll"><canvas class="heat"></canvas></div>' +
      '<div class="legend"><canvas width="256" height="1"></canvas><div class="ticks"></div></div></div></div>';
    const q = (s) => this.el.querySelector(s);
    for (const b of this.el.querySelectorAll("button[data-show]")) {
      b.onclick = () => this.show(b.dataset.show);
    }
    q("button.flip").onclick = () => this.flip();
    q("button.slide").onclick = () => {
      this.slider = !this.slider;
      q("input.split").hidden = !this.slider;
      this.draw();
    };
    q("input.split").oninput = (e) => {
      this.split = Number(e.target.value);
      this.draw();
    };
  }

  // Canvases, zoom, scroll sync, readout and panning: both layouts.
  wire() {
    const q = (s) => this.el.querySelector(s);
    this.canvas = q("canvas.img");
    this.heat = q("canvas.heat");
    for (const c of [this.canvas, this.heat].filter(Boolean)) {
      c.width = this.w;
      c.height = this.h;
    }
    this.scrolls = [...this.el.querySelectorAll(".scroll")];
    q("button.zoom-in").onclick = () => this.setZoom(this.zoom * 2);
    q("button.zoom-out").onclick = () => this.setZoom(this.zoom / 2);
    for (const s of this.scrolls) {
      s.addEventListener("scroll", () => {
        for (const o of this.scrolls) {
          if (o !== s) {
            o.scrollLeft = s.scrollLeft;
            o.scrollTop = s.scrollTop;
          }
        }
      });
      s.addEventListener("wheel", (e) => {
        e.preventDefault();
        this.setZoom(e.deltaY < 0 ? this.zoom * 2 : this.zoom / 2);
      }, { passive: false });
      s.addEventListener("mousemove", (e) => this.readout(e, s));
      s.addEventListener("mouseenter", () => (active = this));
      s.addEventListener("mousedown", (e) => {
        const x0 = e.clientX, y0 = e.clientY, l0 = s.scrollLeft, t0 = s.scrollTop;
        const move = (m) => {
          s.scrollLeft = l0 - (m.clientX - x0);
          s.scrollTop = t0 - (m.clientY - y0);
        };
        const up = () => {
          window.removeEventListener("mousemove", move);
          window.removeEventListener("mouseup", up);
        };
        window.addEventListener("mousemove", move);
        window.addEventListener("mouseup", up);
        e.preventDefault();
      });
    }
    this.setZoom(this.w <= 128 ? 4 : 2);
  }

  setZoom(z) {
    this.zoom = Math.min(32, Math.max(1, z));
    this.el.querySelector(".zv").textContent = this.zoom + "x";
    for (const c of [this.canvas, this.heat].filter(Boolean)) {
      c.style.width = this.w * this.zoom + "px";
      c.style.height = this.h * this.zoom + "px";
    }
    this.mark();
  }

  // A ring around the first NaN/out-of-range pixel, on both views.
  mark() {
    for (const m of this.el.querySelectorAll(".mark")) m.remove();
    if (!this.firstBad) return;
    const [x, y] = this.firstBad;
    const size = Math.max(this.zoom, 8);
    for (const s of this.scrolls) {
      const m = document.createElement("div");
      m.className = "mark";
      m.title = `first bad pixel (${x}, ${y})`;
      m.style.left = x * this.zoom + this.zoom / 2 - size / 2 - 2 + "px";
      m.style.top = y * this.zoom + this.zoom / 2 - size / 2 - 2 + "px";
      m.style.width = m.style.height = size + "px";
      s.appendChild(m);
    }
  }

  show(which) {
    this.showing = which;
    this.el.dataset.showing = which;
    this.draw();
  }

  flip() {
    if (this.alone) return;
    this.show(this.showing === "actual" ? "expected" : "actual");
  }

  draw() {
    if (this.alone) {
      const img = new ImageData(this.w, this.h);
      for (let i = 0; i < this.w * this.h; i++) {
        for (let c = 0; c < 3; c++) img.data[4 * i + c] = Math.round(this.act[3 * i + c] / 257);
        img.data[4 * i + 3] = 255;
      }
      this.canvas.getContext("2d").putImageData(img, 0, 0);
      this.el.querySelector(".img-label").textContent = "actual: no golden of this size yet; review it, then bless it" + this.rows();
      return;
    }
    const img = new ImageData(this.w, this.h);
    const cut = Math.round(this.split * this.w);
    for (let y = 0; y < this.h; y++) {
      for (let x = 0; x < this.w; x++) {
        const i = y * this.w + x;
        const src = this.slider ? (x < cut ? this.exp : this.act) : this.showing === "actual" ? this.act : this.exp;
        for (let c = 0; c < 3; c++) img.data[4 * i + c] = Math.round(src[3 * i + c] / 257);
        img.data[4 * i + 3] = 255;
        if (this.slider && x === cut) img.data.set([255, 0, 0, 255], 4 * i);
      }
    }
    this.canvas.getContext("2d").putImageData(img, 0, 0);
    const label = this.slider ? `slider: expected left, actual right of x = ${cut}` : `showing: ${this.showing}`;
    this.el.querySelector(".img-label").textContent = label + this.rows();
    for (const b of this.el.querySelectorAll("button[data-show]")) b.classList.toggle("on", !this.slider && b.dataset.show === this.showing);
    this.el.dataset.showing = this.showing;
  }

  // Which rows a tall image's viewer holds (the PNG files hold them all).
  rows() {
    return this.fullH > this.h ? ` (rows ${this.y0}-${this.y0 + this.h - 1} of ${this.fullH}; the PNG files hold all)` : "";
  }

  diffAt(i) {
    let d = 0;
    for (let c = 0; c < 3; c++) d = Math.max(d, Math.abs(this.act[3 * i + c] - this.exp[3 * i + c]));
    return d / 65535;
  }

  drawHeat() {
    if (!this.heat || this.alone) return;
    const n = this.w * this.h;
    let max = 1 / 65535;
    for (let i = 0; i < n; i++) max = Math.max(max, this.diffAt(i));
    const mode = heatScale.value;
    const top = mode === "max" ? max : Math.max(Number(heatMax.value) || 1 / 255, 1e-9);
    const pos = mode === "log" ? logPos : (d) => d / top;
    const img = new ImageData(this.w, this.h);
    for (let i = 0; i < n; i++) {
      img.data.set([...colormap(pos(this.diffAt(i))), 255], 4 * i);
    }
    this.heat.getContext("2d").putImageData(img, 0, 0);
    const legend = this.el.querySelector(".legend canvas");
    const bar = new ImageData(256, 1);
    for (let x = 0; x < 256; x++) bar.data.set([...colormap(x / 255), 255], 4 * x);
    legend.getContext("2d").putImageData(bar, 0, 0);
    const ticks = mode === "log"
      ? [[1 / 65535, "1/65535"], [1 / 4096, "1/4096"], [1 / 255, "1/255"], [1 / 16, "1/16"], [1, "1"]]
      : [[0, "0"], [top / 2, (top / 2).toPrecision(3)], [top, top.toPrecision(3)]];
    this.el.querySelector(".ticks").innerHTML = ticks
      .map(([v, t]) => `<span style="left:${(256 * Math.min(1, pos(v))).toFixed(1)}px">${t}</span>`)
      .join("");
  }

  readout(e, scroll) {
    const c = scroll.querySelector("canvas");
    const r = c.getBoundingClientRect();
    const x = Math.floor((e.clientX - r.left) / this.zoom), y = Math.floor((e.clientY - r.top) / this.zoom);
    if (x < 0 || y < 0 || x >= this.w || y >= this.h) return;
    const i = y * this.w + x;
    const px = (a) => [0, 1, 2].map((k) => fmt(a[3 * i + k])).join(" ");
    const at = `(${x}, ${y + this.y0})`;
    if (this.alone) {
      this.el.querySelector(".readout").textContent = `${at}  actual ${px(this.act)}`;
      return;
    }
    const diff = [0, 1, 2].map((k) => {
      const d = this.act[3 * i + k] - this.exp[3 * i + k];
      return (d >= 0 ? "+" : "") + d;
    });
    this.el.querySelector(".readout").textContent =
      `${at}  expected ${px(this.exp)}  actual ${px(this.act)}  diff ${diff.join(" ")} /65535`;
  }
}

for (const el of document.querySelectorAll(".viewer")) {
  const v = new Viewer(el);
  viewers.set(v.id, v);
  const details = el.closest("details");
  if (details.open) v.request();
  details.addEventListener("toggle", () => details.open && v.request());
}

window.vistaCase = (d) => {
  const v = viewers.get(d.id);
  if (v) v.load(d);
};

heatScale.addEventListener("change", () => viewers.forEach((v) => v.drawHeat()));
heatMax.addEventListener("input", () => viewers.forEach((v) => v.drawHeat()));

document.addEventListener("keydown", (e) => {
  if (e.key !== "f" || e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
  const v = active || [...viewers.values()].find((x) => x.canvas && !x.alone);
  if (v && v.canvas) v.flip();
});
