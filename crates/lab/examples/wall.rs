// Temporary experiment harness (not committed).
use histencil_vk::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cov: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(0.001);
    let frames: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(3);
    let scene = histencil_lab::light_size_scene(cov, 16.0 / 9.0);
    let ctx = Context::new(ContextDesc::default()).unwrap();
    let mut r = Renderer::new(&ctx, scene, 1280, 720).unwrap();
    for (name, t) in [
        (
            "tiled16",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Sixteen,
            },
        ),
        (
            "tiled8",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Eight,
            },
        ),
        (
            "stencil",
            Technique::Stencil {
                backend: Backend::Native,
                flush: FlushPolicy::Auto,
            },
        ),
        (
            "branching",
            Technique::Branching {
                backend: Backend::Native,
                flush: FlushPolicy::Auto,
            },
        ),
    ] {
        let desc = FrameDesc {
            pass_timing: true,
            ..FrameDesc::new(t, Readback::NONE)
        };
        if name.starts_with("tiled") {
            let f = r.render_frame(&FrameDesc::new(t, Readback::ALL)).unwrap();
            f.images
                .ldr
                .as_ref()
                .unwrap()
                .save(format!("/tmp/wall-{cov}-{name}.png"))
                .unwrap();
            let h = f.images.hdr.unwrap();
            let n = h.pixels().count() as f64;
            let (a, b) = h
                .pixels()
                .fold((0.0, 0.0), |(a, b), p| (a + p[0] as f64, b + p[1] as f64));
            println!(
                "{name}: mask lights per pixel {:.3}, reaching {:.3}",
                a / n,
                b / n
            );
        }
        let tm = r.measure(desc, frames).unwrap();
        let p: Vec<String> = tm
            .passes
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.1}"))
            .collect();
        println!("{cov} {name}: {}", p.join(", "));
    }
}
