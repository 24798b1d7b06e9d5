//! The browser engine's one executor: the same graph as JSON for
//! `runner.js`'s `vistaRun` (each pass's WGSL as [`crate::TintWgsl`] says, the same resources,
//! contents, bindings, repeats and swaps), the outputs decoded as on wgpu.

use std::sync::Arc;
use std::time::Duration;

use serde_json::{Value, json};

use crate::GpuError;
use crate::context::{BrowserEngine, Context, RunStats, read_texels};
use crate::graph::{Bind, Contents, Graph, GraphPass, GraphSlot, OutputData, Readback, Resource};
use crate::tint::TintWgsl;
use vista_texel::{Access, SampleKind};

impl Context {
    /// The same graph in headless Chromium: each pass's WGSL as Tint gets it, the
    /// same resources, contents, bindings, repeats and swaps (`runner.js`,
    /// `vistaRun`), the outputs decoded as on wgpu.
    pub(crate) fn run_in_browser(
        &self,
        b: &BrowserEngine,
        g: &Graph<'_>,
        which: usize,
    ) -> Result<(Readback, Vec<Vec<usize>>), GpuError> {
        let b64 = vista_browser::base64;
        let mut resources = Vec::new();
        let usages = crate::graph::buffer_usages(&g.resources, &g.passes);
        for (i, r) in g.resources.iter().enumerate() {
            resources.push(match r {
                Resource::Texture(t) => {
                    let format = crate::format::parse(t.format)?;
                    // A sentinel goes as one texel the page repeats.
                    let (contents, fill) = match &t.contents {
                        Contents::Zeros => (None, None),
                        Contents::Bytes(bytes) => (Some(b64(bytes)), None),
                        Contents::Sentinel => (None, Some(b64(&format.sentinel(which)))),
                    };
                    json!({
                        "kind": "texture", "format": t.format, "dimension": t.dimension.texture_name(),
                        "width": t.width, "height": t.height, "layers": t.layers, "mip_levels": t.mip_levels,
                        "texel_bytes": format.texel_bytes(), "storable": format.is_storable(),
                        "contents": contents, "fill": fill,
                    })
                }
                Resource::Buffer(bytes) => json!({
                    "kind": "buffer", "size": bytes.len(), "contents": b64(bytes),
                    "usage": usages[i].unwrap_or_default().web_names(),
                }),
                Resource::Depth([w, h], values) if values.is_empty() => {
                    json!({ "kind": "depth", "width": w, "height": h, "contents": null })
                }
                // First values: the page draws them in with vista's fill pass.
                Resource::Depth([w, h], values) => json!({
                    "kind": "depth", "width": w, "height": h, "contents": b64(values),
                    "fill": {
                        "wgsl": crate::fullscreen::depth_fill_wgsl(),
                        "vertex": crate::fullscreen::FULLSCREEN_ENTRY,
                        "fragment": crate::fullscreen::DEPTH_FILL_ENTRY,
                    },
                }),
                Resource::Sampler(s) => json!({
                    "kind": "sampler",
                    "filter": if s.linear { "linear" } else { "nearest" },
                    "address": s.address.iter().map(|a| a.web()).collect::<Vec<_>>(),
                    "compare": s.compare,
                }),
            });
        }
        let mut passes = Vec::new();
        // Each pass's text by its key, to place Tint's line numbers.
        let mut texts: Vec<(String, Arc<TintWgsl>)> = Vec::new();
        for pass in g.passes.iter() {
            let (key, written) = self.browser_wgsl(b, g, &pass.shader, &pass.entry, &pass.constants)?;
            let slots = pass.slots.iter().map(|s| self.slot_json(b, g, pass, s)).collect::<Result<Vec<_>, _>>()?;
            if let Some(r) = &pass.raster {
                let adapter = || self.adapter_description();
                crate::raster::check_targets(r, &g.resources, &pass.label, &|f| self.has_feature(f), &adapter)?;
                let module = g.shaders.compose(&pass.shader)?;
                crate::raster::check_fragment(&module, &pass.entry, r, &g.resources, &pass.label)?;
            }
            // A vertex entry of another file travels as its own WGSL.
            let vertex_written = match pass.raster.as_ref() {
                Some(r @ crate::graph::Raster { vertex_shader: Some(file), vertex: Some(vs), .. }) => {
                    Some(self.browser_wgsl(b, g, file, vs, &r.vertex_constants)?.1)
                }
                _ => None,
            };
            let raster = pass.raster.as_ref().map(|r| {
                // A vertex entry by the name the written WGSL gives it.
                let vertex = r.vertex.as_deref().map(|vs| match &vertex_written {
                    Some(v) => (Some(v.wgsl.as_str()), v.entry(vs), constants_json(&v.constants)),
                    None => (None, written.entry(vs), constants_json(&written.constants)),
                });
                raster_json(r, vertex)
            });
            texts.push((key.clone(), written.clone()));
            passes.push(json!({
                "key": key, "label": pass.label, "wgsl": written.wgsl, "entry": written.entry(&pass.entry),
                "constants": constants_json(&written.constants),
                "workgroups": pass.workgroups, "repeat": pass.repeat, "span": pass.span,
                "swap": pass.swap.iter().map(|(a, b)| [a, b]).collect::<Vec<_>>(),
                "slots": slots, "raster": raster,
            }));
        }
        // A texture output's level, first layer and extent as the page copies it.
        let outputs: Vec<Value> = g
            .outputs
            .iter()
            .map(|o| match o.texture(&g.resources[o.resource]) {
                Some(t) => json!({
                    "resource": o.resource, "level": o.level, "z": o.first_layer(),
                    "width": t.width, "height": t.height, "layers": t.layers,
                }),
                None => json!({ "resource": o.resource }),
            })
            .collect();
        let job = json!({ "resources": resources, "passes": passes, "outputs": outputs });
        let label = g.passes.first().map(|p| p.shader.clone()).unwrap_or_default();
        let _serial = self.submit_lock.lock().expect("submit lock");
        let out = b.browser.run(&label, &job).map_err(|e| match e {
            vista_browser::BrowserError::Timeout { case, seconds } => GpuError::Timeout { what: case, seconds },
            vista_browser::BrowserError::Page { case, message } => {
                let message = match texts.iter().find(|(key, _)| message.contains(&format!("WGSL of {key}:"))) {
                    Some((key, text)) => text.locate(&message.replace(&format!("WGSL of {key}:"), "WGSL:")),
                    None => message,
                };
                GpuError::Validation { what: format!("{case} (in the browser)"), message }
            }
            other => GpuError::Device { adapter: self.adapter_description(), message: other.to_string() },
        })?;
        let mut outputs = Vec::new();
        let mut sentinels = Vec::new();
        for (&o, bytes) in g.outputs.iter().zip(out.outputs) {
            match o.texture(&g.resources[o.resource]) {
                Some(t) => {
                    let format = crate::format::parse(t.format)?;
                    let row = t.width as usize * format.texel_bytes();
                    let texels =
                        read_texels(&bytes, row, &format, t.width, t.height * t.layers, &format.sentinel(which));
                    sentinels.push(match t.contents {
                        Contents::Sentinel => texels.holding_sentinel,
                        _ => Vec::new(),
                    });
                    outputs.push(OutputData::Texture { image: texels.image, unwritten: 0 });
                }
                None => {
                    sentinels.push(Vec::new());
                    outputs.push(OutputData::Buffer(bytes));
                }
            }
        }
        let kernel: Duration = out.passes.iter().sum();
        let stats = RunStats { gpu_wall: kernel + out.readback, kernel, readback: out.readback, total: out.total };
        let pass_gpu_times = vec![None; out.passes.len()];
        Ok((Readback { outputs, stats, pass_times: out.passes, pass_gpu_times }, sentinels))
    }

    /// A composed file's WGSL for Tint, with its cache key: written once
    /// per engine (a file that needs a feature the browser lacks is
    /// unsupported, checked then).
    fn browser_wgsl(
        &self,
        b: &BrowserEngine,
        g: &Graph<'_>,
        shader: &str,
        entry: &str,
        constants: &[(String, f64)],
    ) -> Result<(String, Arc<TintWgsl>), GpuError> {
        let key = format!("{shader}#{}@{entry}{constants:?}", g.shaders.source_hash(shader)?);
        if let Some(w) = b.sources.lock().expect("wgsl cache").get(&key).cloned() {
            return Ok((key, w));
        }
        self.check_features(shader, [Some(&*g.shaders.compose(shader)?), None])?;
        self.check_declared(shader, &g.shaders.declared_features(shader)?)?;
        let w = Arc::new(Context::wgsl_for_tint(g.shaders, shader, entry, constants)?);
        b.sources.lock().expect("wgsl cache").insert(key.clone(), w.clone());
        Ok((key, w))
    }

    /// One binding as the page takes it: its bind group layout entry, and
    /// its source (a pass's own bytes, or a resource).
    fn slot_json(&self, b: &BrowserEngine, g: &Graph<'_>, pass: &GraphPass, s: &GraphSlot) -> Result<Value, GpuError> {
        let b64 = vista_browser::base64;
        let filterable32 = b.features.iter().any(|f| f == "float32-filterable");

        let texture = |r: usize| match &g.resources[r] {
            Resource::Texture(t) => Ok(t),
            _ => Err(GpuError::Request(format!("{}: a texture binding names a non-texture", pass.label))),
        };
        let (layout, source) = match &s.bind {
            Bind::Uniform(bytes) => (json!({ "buffer": { "type": "uniform" } }), json!({ "owned": b64(bytes) })),
            Bind::Table(words) => {
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                (json!({ "buffer": { "type": "read-only-storage" } }), json!({ "owned": b64(&bytes) }))
            }
            Bind::UniformBuffer(r) => (json!({ "buffer": { "type": "uniform" } }), json!({ "resource": r })),
            Bind::Storage { resource, read_only } => (
                json!({ "buffer": { "type": if *read_only { "read-only-storage" } else { "storage" } } }),
                json!({ "resource": resource }),
            ),
            Bind::StorageTexture { resource, access, level } => {
                let t = texture(*resource)?;
                let format = crate::format::parse(t.format)?;
                if *access == Access::ReadWrite && !self.binds_read_write(&format) {
                    return Err(GpuError::Unsupported {
                        adapter: self.adapter_description(),
                        what: format!("{}: a {} {} storage texture", pass.label, access.wgsl(), t.format),
                        feature: self.read_write_feature().to_string(),
                    });
                }
                let access = access.web();
                (
                    json!({ "storageTexture": { "access": access, "format": t.format, "viewDimension": t.dimension.name() } }),
                    json!({ "resource": resource, "level": level }),
                )
            }
            // A depth resource: texture_depth_2d, or texture_2d<f32> as WebGPU
            // allows (unfilterable-float).
            Bind::Sampled { resource, depth, .. } if matches!(g.resources[*resource], Resource::Depth(..)) => (
                json!({ "texture": {
                    "sampleType": if *depth { "depth" } else { "unfilterable-float" },
                    "viewDimension": "2d", "multisampled": false,
                } }),
                json!({ "resource": resource, "level": null }),
            ),
            Bind::Sampled { resource, depth, view, level } => {
                let t = texture(*resource)?;
                let format = crate::format::parse(t.format)?;
                let sample = match (depth, format.sample_kind()) {
                    (true, _) => "depth",
                    (_, SampleKind::Uint) => "uint",
                    (_, SampleKind::Sint) => "sint",
                    (_, SampleKind::Float) if format.is_float32() && !filterable32 => "unfilterable-float",
                    (_, SampleKind::Float) => "float",
                };
                (
                    json!({ "texture": { "sampleType": sample, "viewDimension": view.unwrap_or(t.dimension).name() } }),
                    json!({ "resource": resource, "level": level }),
                )
            }
            Bind::Sampler(r) => {
                let Resource::Sampler(sd) = &g.resources[*r] else {
                    return Err(GpuError::Request(format!("{}: a sampler bound to a non-sampler", pass.label)));
                };
                let ty = match (sd.compare.is_some(), sd.linear) {
                    (true, _) => "comparison",
                    (false, true) => "filtering",
                    (false, false) => "non-filtering",
                };
                (json!({ "sampler": { "type": ty } }), json!({ "resource": r }))
            }
        };
        let mut slot = json!({ "group": s.group, "binding": s.binding, "layout": layout, "vertex": s.vertex });
        slot.as_object_mut().expect("an object").extend(source.as_object().expect("an object").clone());
        Ok(slot)
    }
}

/// Pipeline constants as WebGPU's `constants` record.
fn constants_json(constants: &[(String, f64)]) -> Value {
    Value::Object(constants.iter().map(|(k, v)| (k.clone(), json!(v))).collect())
}

/// A render pass as the page takes it; `vertex`: the vertex entry's WGSL
/// (when it is another file's), its name in that text and its pipeline
/// constants.
fn raster_json(r: &crate::graph::Raster, vertex: Option<(Option<&str>, &str, Value)>) -> Value {
    let blend = |b: vista_texel::Blend| {
        b.components().map(|(c, a)| {
            let part = |p: vista_texel::BlendComponent| {
                json!({ "srcFactor": p.src.web(), "dstFactor": p.dst.web(), "operation": p.op.web() })
            };
            json!({ "color": part(c), "alpha": part(a) })
        })
    };
    let (vertex, vertex_entry, vertex_constants) =
        vertex.unwrap_or((Some(crate::FULLSCREEN_WGSL), crate::FULLSCREEN_ENTRY, json!({})));
    json!({
        "vertex": vertex, "vertex_entry": vertex_entry, "vertex_constants": vertex_constants,
        "targets": r.targets.iter().map(|t| json!({
            "resource": t.resource, "level": t.level, "layer": t.layer, "clear": t.clear, "clear_once": t.clear_once,
            "blend": blend(t.blend),
        })).collect::<Vec<_>>(),
        "buffers": r.buffers.iter().map(|b| json!({
            "resource": b.resource, "arrayStride": b.stride, "stepMode": if b.instance { "instance" } else { "vertex" },
            "attributes": b.attributes.iter().map(|(l, f, o)| json!({ "shaderLocation": l, "format": f, "offset": o }))
                .collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "indices": r.indices, "index_format": if r.index_u16 { "uint16" } else { "uint32" },
        "count": r.count, "instances": r.instances,
        "first_vertex": r.first_vertex, "first_instance": r.first_instance, "base_vertex": r.base_vertex,
        "topology": r.topology.web(), "cull": r.cull.web(),
        "depth": r.depth.as_ref().map(|d| json!({
            "resource": d.resource, "compare": d.compare, "write": d.write, "clear": d.clear,
        })),
        "blend_constant": r.blend_constant,
    })
}
