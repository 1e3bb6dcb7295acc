//! Declared buffer accesses and the hand-overs derived from them: a step says how it uses a buffer
//! next (the encoder's `Recording::declare_buffers`), and the barrier follows from the buffer's
//! last declared uses, in recording order across command buffers ([`BufferUse`], [`hand_over`],
//! pure and unit-tested).

use ash::vk;

/// How a buffer is used, as [`ImageAccess`](super::ImageAccess) says it of an image: the stages and accesses a
/// barrier between two uses waits for or makes visible (the table kajiya's `vk-sync` keeps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferAccess {
    /// Written by a fill or a copy.
    TransferWrite,
    /// Read by a copy.
    TransferRead,
    /// Read by fragment shaders as a storage buffer.
    FragmentRead,
    /// Read and written (atomics) by fragment shaders as a storage buffer.
    FragmentReadWrite,
    /// Written by compute shaders as a storage buffer.
    ComputeWrite,
    /// Read by compute shaders as a storage buffer.
    ComputeRead,
    /// Read and written (atomics) by compute shaders as a storage buffer.
    ComputeReadWrite,
    /// Read as an indirect dispatch's or draw's arguments.
    IndirectRead,
}

/// The stages and access mask of a [`BufferAccess`]. Pure, so it is unit-tested.
pub fn buffer_access_info(access: BufferAccess) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
    use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
    match access {
        BufferAccess::TransferWrite => (S::ALL_TRANSFER, A::TRANSFER_WRITE),
        BufferAccess::TransferRead => (S::ALL_TRANSFER, A::TRANSFER_READ),
        BufferAccess::FragmentRead => (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ),
        BufferAccess::FragmentReadWrite => (
            S::FRAGMENT_SHADER,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        ),
        BufferAccess::ComputeWrite => (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
        BufferAccess::ComputeRead => (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ),
        BufferAccess::ComputeReadWrite => (
            S::COMPUTE_SHADER,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        ),
        BufferAccess::IndirectRead => (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ),
    }
}

/// What a hazard test leaves out of a declaration (`Recording::declare_buffers_leaving_out`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LeaveOut {
    Barrier,
    Declaration,
}

/// The write accesses histencil's buffers see: what a barrier makes available.
pub(crate) const BUFFER_WRITES: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw() | vk::AccessFlags2::TRANSFER_WRITE.as_raw(),
);

impl BufferAccess {
    /// Whether it writes.
    pub fn writes(self) -> bool {
        let (_, access) = buffer_access_info(self);
        access.intersects(BUFFER_WRITES)
    }
}

/// A buffer's last declared uses: its last write (stages and write accesses), the stages that
/// read it since, and the stages that write was made visible to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct BufferUse {
    write: Option<(vk::PipelineStageFlags2, vk::AccessFlags2)>,
    reads: vk::PipelineStageFlags2,
    visible_to: vk::PipelineStageFlags2,
}

/// A dependency's (stages, accesses) before and after.
type Scopes = (
    (vk::PipelineStageFlags2, vk::AccessFlags2),
    (vk::PipelineStageFlags2, vk::AccessFlags2),
);

/// The barrier a buffer needs between its last declared uses `last` and `next`, and what it
/// has been used as after. Pure, so it is unit-tested: a write waits for the last write and
/// every read since (an execution dependency for those, the write made available); a read
/// waits for the last write unless a barrier made it visible to its stage already; a read
/// after reads needs nothing.
pub(crate) fn hand_over(last: BufferUse, next: BufferAccess) -> (Option<Scopes>, BufferUse) {
    let (stage, access) = buffer_access_info(next);
    if next.writes() {
        let (write_stage, write_access) = last.write.unwrap_or_default();
        let src = (write_stage | last.reads, write_access);
        let barrier = (!src.0.is_empty()).then_some((src, (stage, access)));
        let after = BufferUse {
            write: Some((stage, access & BUFFER_WRITES)),
            reads: vk::PipelineStageFlags2::empty(),
            visible_to: vk::PipelineStageFlags2::empty(),
        };
        return (barrier, after);
    }
    let mut after = BufferUse {
        reads: last.reads | stage,
        ..last
    };
    match last.write {
        Some(write) if !last.visible_to.contains(stage) => {
            after.visible_to |= stage;
            (Some((write, (stage, access))), after)
        }
        _ => (None, after),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declared_buffer_uses_derive_the_hand_overs_they_need_and_no_more() {
        use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
        use BufferAccess::*;
        // The first use of a buffer: nothing before it.
        let (barrier, filled) = hand_over(BufferUse::default(), TransferWrite);
        assert_eq!(barrier, None);
        // Read after the fill: the write made visible to the fragment shader.
        let (barrier, read) = hand_over(filled, FragmentRead);
        let transfer = (S::ALL_TRANSFER, A::TRANSFER_WRITE);
        assert_eq!(
            barrier,
            Some((transfer, (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ)))
        );
        // A second read of the same stage: already visible.
        let (barrier, read) = hand_over(read, FragmentRead);
        assert_eq!(barrier, None);
        // A write after the reads waits for them (execution) and for the fill (memory).
        let (barrier, _) = hand_over(read, TransferWrite);
        let src = (S::ALL_TRANSFER | S::FRAGMENT_SHADER, A::TRANSFER_WRITE);
        assert_eq!(barrier, Some((src, transfer)));
        // Atomics after atomics (the light passes' split): their writes handed over.
        let (_, counted) = hand_over(BufferUse::default(), FragmentReadWrite);
        let (barrier, _) = hand_over(counted, FragmentReadWrite);
        let rw = (
            S::FRAGMENT_SHADER,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        );
        assert_eq!(
            barrier,
            Some(((S::FRAGMENT_SHADER, A::SHADER_STORAGE_WRITE), rw))
        );
    }

    #[test]
    fn buffer_accesses_name_their_stage_and_only_writes_are_made_available() {
        use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
        let all = [
            BufferAccess::TransferWrite,
            BufferAccess::TransferRead,
            BufferAccess::FragmentRead,
            BufferAccess::FragmentReadWrite,
            BufferAccess::ComputeWrite,
            BufferAccess::ComputeRead,
            BufferAccess::ComputeReadWrite,
            BufferAccess::IndirectRead,
        ];
        for access in all {
            let (stage, mask) = buffer_access_info(access);
            assert!(!stage.is_empty() && !mask.is_empty(), "{access:?}");
            assert!(
                !stage.contains(S::ALL_COMMANDS),
                "{access:?}: name the stage"
            );
            let writes = mask.intersects(A::TRANSFER_WRITE | A::SHADER_STORAGE_WRITE);
            let named_write = matches!(
                access,
                BufferAccess::TransferWrite
                    | BufferAccess::FragmentReadWrite
                    | BufferAccess::ComputeWrite
                    | BufferAccess::ComputeReadWrite
            );
            assert_eq!(writes, named_write, "{access:?}");
        }
    }
}
