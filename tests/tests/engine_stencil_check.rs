//! The opt-in stencil check: after a G-buffer pass that writes the stencil as the layout says,
//! the check is clean; after an engine's pass that also sets histencil's culling bit (which once
//! gave a frame 200/255 off forward with no message anywhere), it names the bit and counts every
//! pixel. The copy keeps the image's tracked state true for the lighting's barrier, and the
//! layer stays silent.

use ash::vk;
use histencil_tests::engine::{barrier, Engine};
use histencil_vk::{Context, ImageState, Renderer, StencilCheck};

const SIZE: vk::Extent2D = vk::Extent2D {
    width: 40,
    height: 24,
};

#[test]
fn the_stencil_check_names_a_culling_bit_the_gbuffer_pass_set() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.unwrap();
        let renderer = Renderer::new(&ctx, scene, SIZE.width, SIZE.height).unwrap();
        let layout = *renderer.stencil_layout();
        let images = engine.lighting_targets(SIZE, ctx.depth_stencil_format().vk());
        let mut check = StencilCheck::new(&ctx, layout, SIZE).unwrap();
        let d = &engine.device;
        for culling_set in [false, true] {
            let mut targets = images.refs();
            let (pool, cmd) = engine.command_buffer();
            // SAFETY: the engine's command buffer, recorded here and waited for; the image
            // states tracked in `targets` are true.
            let report = unsafe {
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                renderer.record_gbuffer(cmd, &mut targets).unwrap();
                if culling_set {
                    // An engine pass that writes every pixel's culling bit.
                    let ds = &mut targets.depth_stencil;
                    let attachment = ImageState {
                        layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                        stage: vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                            | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                        access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                            | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
                    };
                    barrier(d, cmd, ds, attachment, false);
                    let stencil = vk::RenderingAttachmentInfo::default()
                        .image_view(ds.view)
                        .image_layout(attachment.layout)
                        .load_op(vk::AttachmentLoadOp::CLEAR)
                        .store_op(vk::AttachmentStoreOp::STORE)
                        .clear_value(vk::ClearValue {
                            depth_stencil: vk::ClearDepthStencilValue {
                                depth: 1.0,
                                stencil: u32::from(layout.culling_mask()),
                            },
                        });
                    let depth = stencil.load_op(vk::AttachmentLoadOp::LOAD);
                    let rendering = vk::RenderingInfo::default()
                        .render_area(SIZE.into())
                        .layer_count(1)
                        .depth_attachment(&depth)
                        .stencil_attachment(&stencil);
                    d.cmd_begin_rendering(cmd, &rendering);
                    d.cmd_end_rendering(cmd);
                }
                check.record(cmd, &mut targets.depth_stencil).unwrap();
                // A second copy before the first was read: refused, the first left whole.
                assert!(check.record(cmd, &mut targets.depth_stencil).is_err());
                engine.submit_and_wait(pool, cmd);
                check.read().unwrap()
            };
            let pixels = u64::from(SIZE.width * SIZE.height);
            assert_eq!(report.pixels, pixels);
            if culling_set {
                assert!(!report.is_clean());
                let bit = layout.culling_mask().trailing_zeros();
                assert_eq!(report.culling_bit, (bit as u8, pixels), "{report}");
                let text = report.to_string();
                assert!(
                    text.contains(&format!(
                        "{pixels} pixels have histencil's culling bit (bit {bit})"
                    )),
                    "{text}"
                );
            } else {
                assert!(report.is_clean(), "{report}");
            }
        }
        // SAFETY: not recorded since the last read.
        assert!(unsafe { check.read() }.is_err(), "nothing to read");
        drop(check);
        drop(renderer);
        images.free(&engine);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}
