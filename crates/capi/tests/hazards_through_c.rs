//! histencil's hazard check through C, as a C engine's debug build uses it: turned on for the
//! context, told of each begin, submit and wait, its findings read back as text. Two tiled
//! frames in flight in two slots are clean; with the classification's rewrite of the tile
//! buffers every slot shares left out (`omit_hand_over`), the check names the hazard across
//! the two submissions, where the validation layer sees nothing.

use ash::vk;
use histencil::vk::{omit_hand_over, HandOver};
use histencil_capi::*;
mod common;

use common::{c_lighting_desc, last_error, record_through_c, with_c_context, FrameInputs};
use std::ffi::c_char;
use std::ptr::null_mut;

/// Two tiled frames, slot 0 then slot 1, both submitted before either is waited for, with the
/// hazard check told of it all; returns its findings' count and text.
fn two_slots_in_flight(omitted: Option<HandOver>) -> (u32, String) {
    use HistencilResult as R;
    let mut found = (0, String::new());
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let desc = HistencilLightingDesc {
            depth_stencil_format: images.refs().depth_stencil.format,
            frames_in_flight: 2,
            hi_stencil: 0,
            ..c_lighting_desc(world, &names)
        };
        let inputs = FrameInputs::new(world, renderer.brdfs());
        let d = &engine.device;
        let slots = engine.frame_slots(2);
        // SAFETY: live handles and structs; each command buffer is the engine's, begun,
        // recorded, submitted and waited for in order, and told to the check as it goes.
        unsafe {
            assert_eq!(histencil_context_check_hazards(c_ctx), R::Success);
            let mut lighting = null_mut();
            let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            let queue = d.get_device_queue(engine.queue_family, 0);
            let mut targets = images.refs();
            let _omitted = omitted.map(omit_hand_over);
            for (slot, (_, cmd, fence)) in slots.iter().enumerate() {
                d.reset_fences(&[*fence]).unwrap();
                let begin = vk::CommandBufferBeginInfo::default();
                d.begin_command_buffer(*cmd, &begin).unwrap();
                assert_eq!(histencil_note_begin(c_ctx, *cmd), R::Success);
                renderer.record_gbuffer(*cmd, &mut targets).unwrap();
                let frame = HistencilFrame {
                    slot: slot as u32,
                    ..inputs.frame(HISTENCIL_TECHNIQUE_TILED, HISTENCIL_PLATFORM_NATIVE)
                };
                record_through_c(lighting, *cmd, &frame, &mut targets);
                d.end_command_buffer(*cmd).unwrap();
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(*cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(queue, &[submit], *fence).unwrap();
                assert_eq!(histencil_note_submit(c_ctx, cmd, 1, *fence), R::Success);
            }
            for (slot, (_, _, fence)) in slots.iter().enumerate() {
                d.wait_for_fences(&[*fence], true, u64::MAX).unwrap();
                assert_eq!(histencil_note_wait(c_ctx, *fence), R::Success);
                assert_eq!(
                    histencil_lighting_slot_finished(lighting, slot as u32),
                    R::Success
                );
            }
            let (mut count, mut needed) = (0, 0);
            let r = histencil_context_hazards(c_ctx, &mut count, null_mut(), 0, &mut needed);
            assert_eq!(r, R::Success, "{}", last_error());
            let mut text = vec![0u8; needed];
            let r = histencil_context_hazards(
                c_ctx,
                &mut count,
                text.as_mut_ptr().cast(),
                needed,
                null_mut(),
            );
            assert_eq!(r, R::Success, "{}", last_error());
            let text = std::ffi::CStr::from_bytes_until_nul(&text).unwrap();
            found = (count, text.to_string_lossy().into_owned());
            assert_eq!(histencil_lighting_destroy(lighting), R::Success);
        }
        engine.free_frame_slots(&slots);
    });
    found
}

#[test]
fn hazard_tile_rewrite_removed_is_found_through_c() {
    let (clean, text) = two_slots_in_flight(None);
    assert_eq!(clean, 0, "{text}");
    assert_eq!(text, "");
    let (count, text) = two_slots_in_flight(Some(HandOver::TileRewrite));
    assert!(count > 0, "no hazard found without the rewrite's hand-over");
    assert!(
        text.contains("HISTENCIL-HAZARD-WRITE-AFTER-READ") && text.contains("tile-classify"),
        "{text}"
    );
    assert_eq!(text.lines().count(), count as usize, "{text}");
}
