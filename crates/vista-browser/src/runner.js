// The page side of vista's browser backend. Rust evaluates these functions
// over the DevTools protocol; each returns a JSON string so that errors come
// back as data, never as an exception the protocol would flatten.
"use strict";

const vista = { device: null, pipelines: new Map(), out: null, lost: null };

function fail(e) {
  return JSON.stringify({ ok: false, error: String((e && e.message) || e) });
}

function fromBase64(s) {
  if (Uint8Array.fromBase64) return Uint8Array.fromBase64(s);
  const bin = atob(s);
  const u8 = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
  return u8;
}

function toBase64(u8) {
  if (u8.toBase64) return u8.toBase64();
  let s = "";
  for (let i = 0; i < u8.length; i += 0x8000) s += String.fromCharCode.apply(null, u8.subarray(i, i + 0x8000));
  return btoa(s);
}

async function vistaInit() {
  try {
    if (!navigator.gpu) throw new Error("navigator.gpu is missing: WebGPU is off (Chromium needs --enable-unsafe-webgpu)");
    const adapter = await navigator.gpu.requestAdapter();
    if (!adapter) throw new Error("requestAdapter() gave no adapter (--use-webgpu-adapter=swiftshader)");
    const l = adapter.limits;
    // Every feature the adapter has: read_write storage formats beyond the
    // core set come with texture-formats-tier2.
    const features = [...adapter.features];
    // Every limit at the adapter's value (as wgpu requests them): a pass
    // with 10 storage buffers runs where the adapter allows it.
    const requiredLimits = {};
    for (const k in l) if (typeof l[k] === "number") requiredLimits[k] = l[k];
    const device = await adapter.requestDevice({ requiredFeatures: features, requiredLimits });
    device.lost.then((info) => {
      vista.lost = `${info.reason}: ${info.message}`;
      vista.device = null;
    });
    vista.device = device;
    vista.pipelines.clear();
    const i = adapter.info;
    return JSON.stringify({
      ok: true,
      vendor: i.vendor,
      architecture: i.architecture,
      device: i.device,
      description: i.description,
      user_agent: navigator.userAgent,
      max_dimension: device.limits.maxTextureDimension2D,
      features: [...device.features],
      limits: Object.fromEntries(Object.keys(requiredLimits).map((k) => [k, device.limits[k]])),
    });
  } catch (e) {
    return fail(e);
  }
}

// A slice of the last output, base64: DevTools messages stay a few MB each.
function vistaChunk(offset, length) {
  return toBase64(vista.out.subarray(offset, offset + length));
}

// A pass graph (SPEC 14; a one-pass kernel is a graph of one pass): job = { resources: [texture | buffer |
// sampler], passes: [{ key, wgsl (the project's text, or naga's rewrite of a composed module), entry, constants (WebGPU
// pipeline constants), workgroups, repeat, span, swap: [[a, b]], slots: [{ group, binding,
// layout, owned (base64) | resource, level (a texture's one mip level, or null: all) }] }], outputs: [{ resource
// (index), and for a texture: level, z (first layer), width, height, layers (of that level) }] }. A texture: { kind, format, dimension, width, height, layers, mip_levels, texel_bytes, contents (base64 or null: zeros), fill (one texel, base64, repeated over
// the texture: the unwritten sentinel; or null) }; a buffer: { kind, contents (base64), usage (WebGPU usage names the passes
// bind it with; copies are added) }, made and bound with exactly its declared bytes; a sampler: { kind,
// filter, address [u, v, w], compare (or null) }; a depth texture: { kind, width, height, contents (f32 values,
// base64, or null), fill ({ wgsl, vertex, fragment }: the pass that draws the values in, with contents) }. Each slot's `layout` is its bind group layout entry (without
// binding and visibility; `vertex`: the render pass's vertex entry reads it too); a texture slot's view
// dimension is its layout's. A render pass has `raster` (SPEC 17): { vertex (WGSL: vista's full-screen triangle or
// another file's; null: vertex_entry is in the pass's own module), vertex_entry, vertex_constants, targets: [{ resource, level, layer, clear, clear_once (the first run only),
// blend (WebGPU's blend state or null) }], buffers: [{ resource, arrayStride, stepMode, attributes }], indices (a
// buffer or null), index_format (uint32 or uint16), count, instances, first_vertex, first_instance, base_vertex, topology, cull, depth ({ resource, compare, write, clear } or null), blend_constant }. Outputs are read back one after another into vista.out: textures
// unpadded, layers stacked; buffers whole.
async function pipeline(pass, resources) {
  const targets = pass.raster ? pass.raster.targets.map((t) => ({ format: resources[t.resource].format, blend: t.blend || undefined })) : null;
  const r = pass.raster;
  const fixed = r ? [r.vertex_entry, r.vertex, r.vertex_constants, r.buffers.map((b) => [b.arrayStride, b.stepMode, b.attributes]), r.topology, r.cull, r.depth, r.indices !== null && r.index_format] : null;
  const key = `${pass.key}@${pass.entry}${JSON.stringify(pass.slots.map((s) => [s.group, s.binding, s.layout, s.vertex]))}${JSON.stringify(targets)}${JSON.stringify(fixed)}`;
  const cached = vista.pipelines.get(key);
  if (cached) return cached;
  const d = vista.device;
  d.pushErrorScope("validation");
  const module = d.createShaderModule({ code: pass.wgsl, label: pass.key });
  const info = await module.getCompilationInfo();
  const errors = info.messages.filter((m) => m.type === "error");
  if (errors.length) {
    await d.popErrorScope();
    const lines = errors.map((m) => `line ${m.lineNum}:${m.linePos}: ${m.message}`);
    throw new Error(`Tint rejected the WGSL of ${pass.key}: ${lines.join("; ")}`);
  }
  const count = pass.slots.reduce((m, s) => Math.max(m, s.group + 1), 0);
  const groups = [];
  for (let g = 0; g < count; g++) {
    const entries = pass.slots
      .filter((s) => s.group === g)
      .map((s) => {
        const S = GPUShaderStage;
        const visibility = pass.raster ? S.FRAGMENT | (s.vertex ? S.VERTEX : 0) : S.COMPUTE;
        return Object.assign({ binding: s.binding, visibility }, s.layout);
      });
    groups.push(d.createBindGroupLayout({ entries }));
  }
  let p;
  try {
    const layout = d.createPipelineLayout({ bindGroupLayouts: groups });
    if (r) {
      // vista's full-screen triangle, or the pass's own vertex entry.
      const vertex = r.vertex ? d.createShaderModule({ code: r.vertex, label: `${pass.key} vertex` }) : module;
      const strip = r.indices !== null && (r.topology === "triangle-strip" || r.topology === "line-strip");
      p = await d.createRenderPipelineAsync({
        layout,
        vertex: { module: vertex, entryPoint: r.vertex_entry, constants: r.vertex_constants, buffers: r.buffers.map((b) => ({ arrayStride: b.arrayStride, stepMode: b.stepMode, attributes: b.attributes })) },
        fragment: { module, entryPoint: pass.entry, constants: pass.constants, targets },
        primitive: { topology: r.topology, cullMode: r.cull, frontFace: "ccw", ...(strip ? { stripIndexFormat: r.index_format } : {}) },
        ...(r.depth ? { depthStencil: { format: "depth32float", depthWriteEnabled: r.depth.write, depthCompare: r.depth.compare } } : {}),
      });
    } else {
      p = await d.createComputePipelineAsync({ layout, compute: { module, entryPoint: pass.entry, constants: pass.constants } });
    }
  } finally {
    const e = await d.popErrorScope();
    if (e) throw new Error(`pipeline of ${pass.key}: ${e.message}`);
  }
  const compiled = { pipeline: p, groups };
  vista.pipelines.set(key, compiled);
  return compiled;
}

async function vistaRun(job) {
  const made = [];
  const scratch = [];
  try {
    const d = vista.device;
    if (!d) throw new Error(`the WebGPU device is gone (${vista.lost || "never created"})`);
    const compiled = [];
    for (const pass of job.passes) compiled.push(await pipeline(pass, job.resources));
    // Textures some render pass draws into.
    const drawn = new Set(job.passes.flatMap((p) => (p.raster ? p.raster.targets.map((t) => t.resource) : [])));
    const start = performance.now();
    d.pushErrorScope("out-of-memory");
    d.pushErrorScope("validation");
    const B = GPUBufferUsage;
    const T = GPUTextureUsage;
    for (const [ri, r] of job.resources.entries()) {
      if (r.kind === "texture") {
        const size = { width: r.width, height: r.height, depthOrArrayLayers: r.layers };
        const usage = (r.storable ? T.STORAGE_BINDING : 0) | T.TEXTURE_BINDING | T.COPY_SRC | T.COPY_DST | (drawn.has(ri) ? T.RENDER_ATTACHMENT : 0);
        const texture = d.createTexture({ size, dimension: r.dimension, format: r.format, usage, mipLevelCount: r.mip_levels });
        const rowBytes = r.width * r.texel_bytes;
        if (r.contents) {
          d.queue.writeTexture({ texture }, fromBase64(r.contents), { bytesPerRow: rowBytes, rowsPerImage: r.height }, size);
        } else if (r.fill) {
          // Every texel starts as the sentinel texel, so Rust can count those never written.
          const texel = fromBase64(r.fill);
          const filled = new Uint8Array(rowBytes * r.height * r.layers);
          for (let i = 0; i < filled.length; i += texel.length) filled.set(texel, i);
          d.queue.writeTexture({ texture }, filled, { bytesPerRow: rowBytes, rowsPerImage: r.height }, size);
        }
        made.push(texture);
      } else if (r.kind === "depth") {
        // Cleared by the pass that tests against it; sampled as texture_depth_2d.
        const texture = d.createTexture({ size: [r.width, r.height], format: "depth32float", usage: T.RENDER_ATTACHMENT | T.TEXTURE_BINDING | T.COPY_SRC });
        if (r.contents) {
          // WebGPU copies into no depth32float texture: an r32float texture of
          // the values is drawn into it, each texel's value as frag_depth.
          const values = d.createTexture({ size: [r.width, r.height], format: "r32float", usage: T.TEXTURE_BINDING | T.COPY_DST });
          scratch.push(values);
          d.queue.writeTexture({ texture: values }, fromBase64(r.contents), { bytesPerRow: r.width * 4, rowsPerImage: r.height }, [r.width, r.height]);
          const module = d.createShaderModule({ code: r.fill.wgsl });
          const layout = d.createBindGroupLayout({ entries: [{ binding: 0, visibility: GPUShaderStage.FRAGMENT, texture: { sampleType: "unfilterable-float" } }] });
          const pipeline = d.createRenderPipeline({
            layout: d.createPipelineLayout({ bindGroupLayouts: [layout] }),
            vertex: { module, entryPoint: r.fill.vertex },
            fragment: { module, entryPoint: r.fill.fragment, targets: [] },
            depthStencil: { format: "depth32float", depthWriteEnabled: true, depthCompare: "always" },
          });
          const group = d.createBindGroup({ layout, entries: [{ binding: 0, resource: values.createView() }] });
          const encoder = d.createCommandEncoder();
          const fill = encoder.beginRenderPass({ colorAttachments: [], depthStencilAttachment: { view: texture.createView(), depthClearValue: 1, depthLoadOp: "clear", depthStoreOp: "store" } });
          fill.setPipeline(pipeline);
          fill.setBindGroup(0, group);
          fill.draw(3);
          fill.end();
          d.queue.submit([encoder.finish()]);
        }
        made.push(texture);
      } else if (r.kind === "buffer") {
        const bytes = fromBase64(r.contents);
        const usage = r.usage.reduce((u, name) => u | B[name], B.COPY_SRC | B.COPY_DST);
        const buffer = d.createBuffer({ size: Math.max(4, Math.ceil(bytes.length / 4) * 4), usage, mappedAtCreation: true });
        new Uint8Array(buffer.getMappedRange()).set(bytes);
        buffer.unmap();
        made.push(buffer);
      } else {
        const desc = { addressModeU: r.address[0], addressModeV: r.address[1], addressModeW: r.address[2], magFilter: r.filter, minFilter: r.filter, mipmapFilter: r.filter };
        if (r.compare) desc.compare = r.compare;
        made.push(d.createSampler(desc));
      }
    }
    const current = job.resources.map((_, i) => i);
    const owned = job.passes.map((pass) =>
      pass.slots.map((s) => {
        if (s.owned === undefined || s.owned === null) return null;
        const bytes = fromBase64(s.owned);
        const usage = s.layout.buffer.type === "uniform" ? B.UNIFORM : B.STORAGE;
        const buffer = d.createBuffer({ size: Math.max(4, Math.ceil(bytes.length / 4) * 4), usage, mappedAtCreation: true });
        new Uint8Array(buffer.getMappedRange()).set(bytes);
        buffer.unmap();
        scratch.push(buffer);
        return buffer;
      }),
    );
    const setup = await d.popErrorScope();
    const setupOom = await d.popErrorScope();
    if (setup) throw new Error(`WebGPU validation (resources): ${setup.message}`);
    if (setupOom) throw new Error(`WebGPU out of memory (resources): ${setupOom.message}`);
    await d.queue.onSubmittedWorkDone();
    // Each group (a pass with span n and the n - 1 after it) runs `repeat`
    // times over; a pass alone (span 1) `repeat` times in a row.
    const order = [];
    for (let first = 0; first < job.passes.length; ) {
      const span = Math.min(Math.max(1, job.passes[first].span), job.passes.length - first);
      for (let run = 0; run < job.passes[first].repeat; run++) for (let p = first; p < first + span; p++) order.push(p);
      first += span;
    }
    const passMs = job.passes.map(() => 0);
    const ran = new Set();
    for (const p of order) {
      const pass = job.passes[p];
      const firstRun = !ran.has(p);
      ran.add(p);
      const passStart = performance.now();
      {
        d.pushErrorScope("validation");
        const resource = (s, i) => {
          // A buffer binding covers the whole buffer: its declared bytes.
          if (owned[p][i]) return { buffer: owned[p][i], size: owned[p][i].size };
          const r = made[current[s.resource]];
          if (s.layout.buffer) return { buffer: r, size: r.size };
          if (s.layout.sampler) return r;
          const dim = (s.layout.texture || s.layout.storageTexture).viewDimension;
          // One level (a storage binding's, or `name@level`), else all of them.
          const level = s.level === null || s.level === undefined ? {} : { baseMipLevel: s.level, mipLevelCount: 1 };
          return r.createView({ dimension: dim, ...level });
        };
        const bindGroups = compiled[p].groups.map((layout, g) =>
          d.createBindGroup({
            layout,
            entries: pass.slots.map((s, i) => [s, i]).filter(([s]) => s.group === g).map(([s, i]) => ({ binding: s.binding, resource: resource(s, i) })),
          }),
        );
        const encoder = d.createCommandEncoder();
        if (pass.raster) {
          // Each target's level, cleared where it says so, else drawn over.
          const colorAttachments = pass.raster.targets.map((t) => {
            const view = made[current[t.resource]].createView({ dimension: "2d", baseMipLevel: t.level, mipLevelCount: 1, baseArrayLayer: t.layer, arrayLayerCount: 1 });
            return t.clear && (firstRun || !t.clear_once)
              ? { view, loadOp: "clear", clearValue: t.clear, storeOp: "store" }
              : { view, loadOp: "load", storeOp: "store" };
          });
          const r = pass.raster;
          // The depth resource (a pass's own buffer is one the plan adds).
          const depthStencilAttachment = r.depth && {
            view: made[current[r.depth.resource]].createView(), depthClearValue: r.depth.clear, depthLoadOp: "clear", depthStoreOp: "store",
          };
          const rp = encoder.beginRenderPass({ colorAttachments, ...(depthStencilAttachment ? { depthStencilAttachment } : {}) });
          rp.setPipeline(compiled[p].pipeline);
          bindGroups.forEach((group, g) => rp.setBindGroup(g, group));
          if (r.blend_constant) rp.setBlendConstant(r.blend_constant);
          r.buffers.forEach((b, slot) => rp.setVertexBuffer(slot, made[current[b.resource]]));
          if (r.indices !== null) {
            rp.setIndexBuffer(made[current[r.indices]], r.index_format);
            rp.drawIndexed(r.count, r.instances, 0, r.base_vertex, r.first_instance);
          } else {
            rp.draw(r.count, r.instances, r.first_vertex, r.first_instance);
          }
          rp.end();
        } else {
          const cp = encoder.beginComputePass();
          cp.setPipeline(compiled[p].pipeline);
          bindGroups.forEach((group, g) => cp.setBindGroup(g, group));
          cp.dispatchWorkgroups(pass.workgroups[0], pass.workgroups[1], pass.workgroups[2]);
          cp.end();
        }
        const e = await d.popErrorScope();
        if (e) throw new Error(`WebGPU validation (${pass.label}): ${e.message}`);
        d.queue.submit([encoder.finish()]);
        await d.queue.onSubmittedWorkDone();
        for (const [a, b] of pass.swap) [current[a], current[b]] = [current[b], current[a]];
      }
      passMs[p] += performance.now() - passStart;
    }
    const copyStart = performance.now();
    const parts = [];
    for (const o of job.outputs) {
      const r = job.resources[o.resource];
      const physical = made[current[o.resource]];
      const encoder = d.createCommandEncoder();
      let readback;
      let unpad = null;
      if (r.kind === "texture" || r.kind === "depth") {
        // A depth texture's depth aspect reads back as 4-byte floats.
        // One mip level, one layer or all (o.z the first), as the host computed them.
        const [texelBytes, layers] = r.kind === "depth" ? [4, 1] : [r.texel_bytes, o.layers];
        const rowBytes = o.width * texelBytes;
        const paddedRow = Math.ceil(rowBytes / 256) * 256;
        const rows = o.height * layers;
        readback = d.createBuffer({ size: paddedRow * rows, usage: B.COPY_DST | B.MAP_READ });
        const size = { width: o.width, height: o.height, depthOrArrayLayers: layers };
        const source = { texture: physical, mipLevel: o.level, origin: { x: 0, y: 0, z: o.z }, aspect: r.kind === "depth" ? "depth-only" : "all" };
        encoder.copyTextureToBuffer(source, { buffer: readback, bytesPerRow: paddedRow, rowsPerImage: o.height }, size);
        unpad = { rowBytes, paddedRow, rows };
      } else {
        const size = Math.max(4, Math.ceil(r.size / 4) * 4);
        readback = d.createBuffer({ size, usage: B.COPY_DST | B.MAP_READ });
        encoder.copyBufferToBuffer(physical, 0, readback, 0, size);
      }
      scratch.push(readback);
      d.queue.submit([encoder.finish()]);
      await readback.mapAsync(GPUMapMode.READ);
      const mapped = new Uint8Array(readback.getMappedRange());
      if (unpad) {
        const out = new Uint8Array(unpad.rowBytes * unpad.rows);
        for (let y = 0; y < unpad.rows; y++) out.set(mapped.subarray(y * unpad.paddedRow, y * unpad.paddedRow + unpad.rowBytes), y * unpad.rowBytes);
        parts.push(out);
      } else {
        parts.push(mapped.slice(0, r.size));
      }
      readback.unmap();
    }
    const total = parts.reduce((n, p) => n + p.length, 0);
    const out = new Uint8Array(total);
    let at = 0;
    for (const p of parts) {
      out.set(p, at);
      at += p.length;
    }
    if (!vista.device) throw new Error(`the WebGPU device was lost during the run (${vista.lost})`);
    vista.out = out;
    return JSON.stringify({ ok: true, pass_ms: passMs, readback_ms: performance.now() - copyStart, total_ms: performance.now() - start, lengths: parts.map((p) => p.length), bytes: total });
  } catch (e) {
    return fail(e);
  } finally {
    for (const x of [...made, ...scratch]) if (x && x.destroy) x.destroy();
  }
}
