//! The `engine_plan` target: what an engine hands the planner each frame, as plain data it
//! builds itself (a stencil layout, lights, each BRDF's boxes, a camera's matrices, a platform's
//! caps, a technique and flush policy), read from JSON so that AFL++'s dictionary reaches the
//! fields. Whatever the numbers, `plan_frame` must answer without a panic; a plan it accepts
//! must hold only indices the recording can follow (each step's light into the plan's lights,
//! each planned light into the engine's, each pass's BRDF slot into the layout's BRDFs): the
//! class of the panic an outside engine hit (a BRDF slot with no BRDF, index 5 of 5).

use histencil_model::{
    plan_frame, Aabb, CompareOp, DepthConvention, FlushPolicy, LightShape, PassKind, PlanInputs,
    PlanSettings, PlatformCaps, Shader, StencilLayout, Step, TechniqueChoice, View, ViewDesc,
};
use serde_json::Value;

fn number(v: &Value) -> f32 {
    v.as_f64().unwrap_or(0.0) as f32
}

fn vec3(v: &Value) -> [f32; 3] {
    let at = |i| v.get(i).map_or(0.0, number);
    [at(0), at(1), at(2)]
}

fn matrix(v: &Value) -> [[f32; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    for (i, x) in v.as_array().into_iter().flatten().take(16).enumerate() {
        m[i / 4][i % 4] = number(x);
    }
    m
}

fn light(v: &Value) -> LightShape {
    let range = v.get("range").map_or(1.0, number);
    let position = v.get("position").map_or([0.0; 3], vec3);
    match v.get("kind").and_then(Value::as_str) {
        Some("spot") => LightShape::Spot {
            position,
            direction: v.get("direction").map_or([0.0, 0.0, -1.0], vec3),
            range,
            outer_angle: v.get("outer").map_or(0.5, number),
        },
        Some("directional") => LightShape::Directional,
        _ => LightShape::Point { position, range },
    }
}

fn caps(v: &Value) -> PlatformCaps {
    let flag = |name| v.get(name).and_then(Value::as_bool).unwrap_or(false);
    const ALL: &[CompareOp] = &[
        CompareOp::Never,
        CompareOp::Less,
        CompareOp::Equal,
        CompareOp::LessOrEqual,
        CompareOp::Greater,
        CompareOp::NotEqual,
    ];
    const EQUAL: &[CompareOp] = &[CompareOp::Equal, CompareOp::NotEqual];
    PlatformCaps {
        hi_stencil: flag("hi_stencil"),
        hi_stencil_read_mask: flag("read_mask"),
        hi_stencil_compares: if flag("all_compares") { ALL } else { EQUAL },
        zero_preserved_as_we_go: flag("zero"),
        save_restore_preserved: flag("save_restore"),
    }
}

/// Plans what `data` describes, and holds an accepted plan's indices.
pub fn engine_plan(data: &[u8]) {
    let Ok(doc) = serde_json::from_slice::<Value>(data) else {
        return;
    };
    let int = |name| doc.get(name).and_then(Value::as_u64).unwrap_or(1) as u32;
    let Ok(layout) = StencilLayout::new(int("brdfs"), int("engine_bits")) else {
        return;
    };
    let lights: Vec<LightShape> = (doc.get("lights").and_then(Value::as_array))
        .into_iter()
        .flatten()
        .take(4096)
        .map(light)
        .collect();
    let bounds: Vec<Vec<Aabb>> = (doc.get("bounds").and_then(Value::as_array))
        .into_iter()
        .flatten()
        .take(64)
        .map(|boxes| {
            (boxes.as_array().into_iter().flatten().take(256))
                .map(|b| Aabb {
                    min: b.get(0).map_or([0.0; 3], vec3),
                    max: b.get(1).map_or([0.0; 3], vec3),
                })
                .collect()
        })
        .collect();
    let view = ViewDesc {
        world_to_view: doc.get("world_to_view").map_or([[0.0; 4]; 4], matrix),
        view_to_clip: doc.get("view_to_clip").map_or([[0.0; 4]; 4], matrix),
        depth: if doc.get("reversed").and_then(Value::as_bool) == Some(true) {
            DepthConvention::Reversed
        } else {
            DepthConvention::Standard
        },
    };
    let Ok(view) = View::new(&view) else {
        return;
    };
    let settings = PlanSettings {
        technique: match doc.get("technique").and_then(Value::as_str) {
            Some("branching") => TechniqueChoice::Branching,
            _ => TechniqueChoice::Stencil,
        },
        caps: doc.get("caps").map_or_else(|| caps(&Value::Null), caps),
        flush: match doc.get("flush").and_then(Value::as_str) {
            Some("always") => FlushPolicy::Always,
            Some("never") => FlushPolicy::Never,
            _ => FlushPolicy::Auto,
        },
    };
    let inputs = PlanInputs {
        lights: &lights,
        brdf_bounds: &bounds,
        view: &view,
    };
    let Ok(plan) = plan_frame(&layout, &inputs, &settings) else {
        return;
    };
    let slots = layout.brdfs_in_use();
    for l in &plan.lights {
        assert!(
            l.input < lights.len(),
            "planned light {} of {}",
            l.input,
            lights.len()
        );
    }
    for step in &plan.steps {
        if let Step::Pass { light, pass } = step {
            assert!(
                *light < plan.lights.len(),
                "step light {light} of {}",
                plan.lights.len()
            );
            if let PassKind::Mask(Shader::Brdf(s)) | PassKind::Shade(Shader::Brdf(s)) = pass.kind {
                assert!(s < slots, "BRDF slot {s} of {slots}");
            }
        }
    }
}
