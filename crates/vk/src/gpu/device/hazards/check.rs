//! The hazard check's rule, as a pure function of a queue's events: every buffer access, and
//! every barrier, in submission order. A later access to a buffer must be ordered after every
//! earlier one it conflicts with (read after write, write after read, write after write) by a
//! chain of barriers whose first scope holds the earlier access's stage and whose last scope
//! holds the later one's; after a write, that chain must also have made the write available
//! (a global or buffer memory barrier naming the write's stage and access) and visible to the
//! later access. Vulkan's rule, as the specification's chapter on synchronisation states it
//! (execution dependency chains, availability and visibility operations), kept small enough
//! to test by hand: one stage per access, whole buffers, no semaphores.
//!
//! A host wait on a fence completes every earlier submission waited on ([`Tracker::complete`]):
//! accesses from it no longer conflict.

use ash::vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
use std::collections::HashMap;

/// One command's use of one buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Access {
    /// The buffer's raw handle.
    pub buffer: u64,
    /// The stage that reads or writes it: one bit.
    pub stage: S,
    /// The read or write accesses (`SHADER_STORAGE_WRITE`, `TRANSFER_READ`, ...).
    pub access: A,
    /// Whether `access` writes.
    pub write: bool,
    /// Whether the shader reaches it by atomic operations alone: two atomic accesses at
    /// device scope are no data race (the Vulkan memory model's definition), so they need no
    /// dependency between them; an atomic and a plain access do.
    pub atomic: bool,
    /// Whether its atomics follow a protocol across commands that needs them in order (the
    /// hi-stencil statistics' stamps): two such need an execution dependency, no more.
    pub ordered: bool,
    /// Where: the open debug labels and what bound the buffer (`tiled-classify: set 2 binding
    /// 1`, `fill`).
    pub at: String,
}

/// One barrier of a barrier command: its scopes, and whose memory it makes available and
/// visible (`Memory::Global` for a memory barrier, one buffer for a buffer barrier, `None` for
/// an image barrier, which orders execution only as far as buffers go).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Dependency {
    pub src: (S, A),
    pub dst: (S, A),
    pub memory: Memory,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Memory {
    Global,
    Buffer(u64),
    None,
}

/// What a queue did, in submission order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Event {
    Access(Access),
    /// One `vkCmdPipelineBarrier2`: its barriers take effect together.
    Barrier(Vec<Dependency>),
}

/// A conflict with no covering dependency.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Hazard {
    /// `READ-AFTER-WRITE`, `WRITE-AFTER-READ` or `WRITE-AFTER-WRITE`.
    pub kind: &'static str,
    pub earlier: Access,
    pub later: Access,
}

/// An earlier access still able to conflict, and what the barriers since have done for it.
#[derive(Clone, Debug)]
struct Pending {
    access: Access,
    /// The submission it was recorded in (completed by a fence wait).
    submission: u64,
    /// Stages of later commands ordered after it (logically later stages included).
    ordered_before: S,
    /// A write made available by a barrier naming its stage and access.
    available: bool,
    /// The (stages, accesses) its write was made visible to.
    visible: Vec<(S, A)>,
}

/// The buffers' earlier accesses, as barriers and fence waits leave them.
#[derive(Default, Debug)]
pub(crate) struct Tracker {
    pending: HashMap<u64, Vec<Pending>>,
}

const GRAPHICS_ORDER: [S; 7] = [
    S::DRAW_INDIRECT,
    S::VERTEX_INPUT,
    S::VERTEX_SHADER,
    S::EARLY_FRAGMENT_TESTS,
    S::FRAGMENT_SHADER,
    S::LATE_FRAGMENT_TESTS,
    S::COLOR_ATTACHMENT_OUTPUT,
];
const COMPUTE_ORDER: [S; 2] = [S::DRAW_INDIRECT, S::COMPUTE_SHADER];

/// What the meta-stages stand for, among the stages histencil records in.
fn unfold(mask: S) -> S {
    let mut out = mask;
    if mask.contains(S::ALL_COMMANDS) {
        out |= S::from_raw(!0);
    }
    if mask.contains(S::ALL_GRAPHICS) {
        out |= GRAPHICS_ORDER.iter().fold(S::empty(), |m, s| m | *s);
    }
    if mask.contains(S::ALL_TRANSFER) {
        out |= S::COPY | S::CLEAR | S::BLIT | S::RESOLVE;
    }
    if mask.intersects(S::COPY | S::CLEAR | S::BLIT | S::RESOLVE) {
        out |= S::ALL_TRANSFER;
    }
    out
}

/// `mask` with every stage logically earlier than one of its own (a first scope), or later
/// (a second scope).
fn widen(mask: S, later: bool) -> S {
    let mut out = unfold(mask);
    for order in [&GRAPHICS_ORDER[..], &COMPUTE_ORDER[..]] {
        for (i, stage) in order.iter().enumerate() {
            if out.contains(*stage) {
                let rest = if later { &order[i..] } else { &order[..=i] };
                out |= rest.iter().fold(S::empty(), |m, s| m | *s);
            }
        }
    }
    out
}

/// Whether an access mask covers `access`: `MEMORY_READ`/`MEMORY_WRITE` and `SHADER_READ`/
/// `SHADER_WRITE` stand for the narrower ones.
fn covers(mask: A, access: A) -> bool {
    let reads = A::SHADER_STORAGE_READ
        | A::UNIFORM_READ
        | A::SHADER_SAMPLED_READ
        | A::INDIRECT_COMMAND_READ
        | A::INDEX_READ
        | A::VERTEX_ATTRIBUTE_READ
        | A::TRANSFER_READ;
    let writes = crate::gpu::access::BUFFER_WRITES;
    let mut full = mask;
    if mask.contains(A::MEMORY_READ) {
        full |= reads;
    }
    if mask.contains(A::MEMORY_WRITE) {
        full |= writes;
    }
    if mask.contains(A::SHADER_READ) {
        full |= A::SHADER_STORAGE_READ | A::UNIFORM_READ | A::SHADER_SAMPLED_READ;
    }
    if mask.contains(A::SHADER_WRITE) {
        full |= A::SHADER_STORAGE_WRITE;
    }
    full.contains(access)
}

impl Tracker {
    /// Applies `event` of `submission`, returning the hazards an access meets.
    pub fn apply(&mut self, event: &Event, submission: u64) -> Vec<Hazard> {
        match event {
            Event::Barrier(dependencies) => {
                self.barrier(dependencies);
                Vec::new()
            }
            Event::Access(access) => self.access(access, submission),
        }
    }

    fn barrier(&mut self, dependencies: &[Dependency]) {
        for (buffer, pending) in &mut self.pending {
            for p in pending {
                // Every barrier of the command sees the state before the command.
                let (mut ordered, mut available, mut visible) =
                    (p.ordered_before, p.available, Vec::new());
                let reached = unfold(p.access.stage) | p.ordered_before;
                for d in dependencies {
                    if !widen(d.src.0, false).intersects(reached) {
                        continue;
                    }
                    ordered |= widen(d.dst.0, true);
                    let memory = match d.memory {
                        Memory::Global => true,
                        Memory::Buffer(b) => b == *buffer,
                        Memory::None => false,
                    };
                    if !(memory && p.access.write) {
                        continue;
                    }
                    let direct = unfold(d.src.0).contains(p.access.stage);
                    let writes = p.access.access & crate::gpu::access::BUFFER_WRITES;
                    let made_available = direct && covers(d.src.1, writes);
                    if p.available || made_available {
                        available = true;
                        // Visibility reaches the named stages only, not the later ones.
                        visible.push((unfold(d.dst.0), d.dst.1));
                    }
                }
                p.ordered_before = ordered;
                p.available = available;
                // One entry per set of stages: a write that stays pending across many barriers
                // (an engine that reports no waits) keeps a bounded list.
                for (stages, access) in visible {
                    match p.visible.iter_mut().find(|(s, _)| *s == stages) {
                        Some(entry) => entry.1 |= access,
                        None => p.visible.push((stages, access)),
                    }
                }
            }
        }
    }

    fn access(&mut self, later: &Access, submission: u64) -> Vec<Hazard> {
        let pending = self.pending.entry(later.buffer).or_default();
        let mut hazards = Vec::new();
        for p in pending.iter() {
            let earlier = &p.access;
            if !(earlier.write || later.write) {
                continue;
            }
            let atomics = earlier.atomic && later.atomic;
            if atomics && !(earlier.ordered && later.ordered) {
                continue;
            }
            let ordered = unfold(p.ordered_before).contains(later.stage);
            let seen = !earlier.write
                || atomics
                || p.visible
                    .iter()
                    .any(|(s, a)| unfold(*s).contains(later.stage) && covers(*a, later.access));
            if !(ordered && seen) {
                let kind = match (earlier.write, later.write) {
                    (true, true) => "WRITE-AFTER-WRITE",
                    (true, false) => "READ-AFTER-WRITE",
                    _ => "WRITE-AFTER-READ",
                };
                hazards.push(Hazard {
                    kind,
                    earlier: earlier.clone(),
                    later: later.clone(),
                });
            }
        }
        let fresh = Pending {
            access: later.clone(),
            submission,
            ordered_before: S::empty(),
            available: false,
            visible: Vec::new(),
        };
        if later.write {
            // Everything before is ordered before this write (or reported): the write stands
            // for it from here on.
            pending.clear();
        } else {
            // An earlier read of the same stage and access is ordered before whatever this one
            // is: this one stands for both.
            pending.retain(|p| {
                p.access.write || p.access.stage != later.stage || p.access.access != later.access
            });
        }
        pending.push(fresh);
        hazards
    }

    /// Forgets the accesses of `submissions`, which a fence wait saw complete.
    pub fn complete(&mut self, submissions: &[u64]) {
        for pending in self.pending.values_mut() {
            pending.retain(|p| !submissions.contains(&p.submission));
        }
        self.pending.retain(|_, p| !p.is_empty());
    }

    /// Forgets `buffer`, destroyed (its handle may come back as another buffer).
    pub fn forget(&mut self, buffer: u64) {
        self.pending.remove(&buffer);
    }

    /// Forgets everything: the device is idle.
    pub fn clear(&mut self) {
        self.pending.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access(stage: S, access: A, write: bool) -> Event {
        Event::Access(Access {
            buffer: 7,
            stage,
            access,
            write,
            atomic: false,
            ordered: false,
            at: String::new(),
        })
    }
    fn run(events: &[Event]) -> Vec<&'static str> {
        let mut t = Tracker::default();
        events
            .iter()
            .flat_map(|e| t.apply(e, 1))
            .map(|h| h.kind)
            .collect()
    }
    fn barrier(src: (S, A), dst: (S, A), memory: Memory) -> Event {
        Event::Barrier(vec![Dependency { src, dst, memory }])
    }
    const CW: (S, A) = (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE);
    const FR: (S, A) = (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ);

    #[test]
    fn a_read_after_a_write_needs_a_memory_dependency() {
        let w = access(CW.0, CW.1, true);
        let r = access(FR.0, FR.1, false);
        assert_eq!(run(&[w.clone(), r.clone()]), ["READ-AFTER-WRITE"]);
        let exact = barrier(CW, FR, Memory::Buffer(7));
        assert!(run(&[w.clone(), exact, r.clone()]).is_empty());
        // Another buffer's barrier orders execution but makes nothing of this one visible.
        let other = barrier(CW, FR, Memory::Buffer(8));
        assert_eq!(run(&[w.clone(), other, r.clone()]), ["READ-AFTER-WRITE"]);
        // The wrong source access: the write is not made available.
        let wrong = barrier((CW.0, A::SHADER_STORAGE_READ), FR, Memory::Global);
        assert_eq!(run(&[w.clone(), wrong, r.clone()]), ["READ-AFTER-WRITE"]);
        // Made visible to the vertex shader: the fragment shader runs after it, but the
        // access scope holds the named stage alone.
        let early = barrier(CW, (S::VERTEX_SHADER, FR.1), Memory::Global);
        assert_eq!(run(&[w.clone(), early, r.clone()]), ["READ-AFTER-WRITE"]);
        let late = barrier(CW, (S::COLOR_ATTACHMENT_OUTPUT, FR.1), Memory::Global);
        assert_eq!(run(&[w, late, r]), ["READ-AFTER-WRITE"]);
    }

    #[test]
    fn a_write_after_a_read_needs_only_execution_order_and_chains_count() {
        let r = access(FR.0, FR.1, false);
        let w = access(S::ALL_TRANSFER, A::TRANSFER_WRITE, true);
        assert_eq!(run(&[r.clone(), w.clone()]), ["WRITE-AFTER-READ"]);
        let image_only = barrier(FR, (S::ALL_TRANSFER, A::TRANSFER_WRITE), Memory::None);
        assert!(run(&[r.clone(), image_only, w.clone()]).is_empty());
        // Fragment -> compute, then compute -> transfer: a chain.
        let one = barrier(FR, CW, Memory::None);
        let two = barrier(CW, (S::ALL_TRANSFER, A::TRANSFER_WRITE), Memory::None);
        assert!(run(&[r.clone(), one.clone(), two, w.clone()]).is_empty());
        // A barrier from another stage does not chain.
        let unrelated = barrier(
            (S::VERTEX_SHADER, A::empty()),
            (S::ALL_TRANSFER, A::TRANSFER_WRITE),
            Memory::Global,
        );
        assert_eq!(run(&[r, one, unrelated, w]), ["WRITE-AFTER-READ"]);
    }

    #[test]
    fn a_global_barrier_of_every_stage_covers_everything_and_a_fence_wait_too() {
        let w = access(CW.0, CW.1, true);
        let r = access(FR.0, FR.1, false);
        let all = barrier(
            (S::ALL_COMMANDS, A::MEMORY_WRITE),
            (S::ALL_COMMANDS, A::MEMORY_READ | A::MEMORY_WRITE),
            Memory::Global,
        );
        assert!(run(&[w.clone(), all.clone(), r.clone(), all, w.clone()]).is_empty());
        let mut t = Tracker::default();
        assert!(t.apply(&w, 1).is_empty());
        t.complete(&[1]);
        assert!(t.apply(&r, 2).is_empty());
        assert!(
            !t.apply(&w, 2).is_empty(),
            "the read of submission 2 is pending"
        );
    }

    #[test]
    fn a_write_made_available_earlier_is_made_visible_by_a_later_chained_barrier() {
        let w = access(CW.0, CW.1, true);
        let r = access(FR.0, FR.1, false);
        let make_available = barrier(CW, (S::COMPUTE_SHADER, A::empty()), Memory::Global);
        let make_visible = barrier((S::COMPUTE_SHADER, A::empty()), FR, Memory::Global);
        assert!(run(&[w.clone(), make_available, make_visible.clone(), r.clone()]).is_empty());
        // Without the availability, the chain orders execution but the read sees stale memory.
        let order_only = barrier(
            (CW.0, A::empty()),
            (S::COMPUTE_SHADER, A::empty()),
            Memory::Global,
        );
        assert_eq!(run(&[w, order_only, make_visible, r]), ["READ-AFTER-WRITE"]);
    }

    #[test]
    fn atomics_need_no_dependency_between_them_but_a_plain_access_after_them_does() {
        let atomic = |stage| {
            Event::Access(Access {
                buffer: 7,
                stage,
                access: A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                write: true,
                atomic: true,
                ordered: false,
                at: String::new(),
            })
        };
        let counted = [atomic(S::FRAGMENT_SHADER), atomic(S::FRAGMENT_SHADER)];
        assert!(run(&counted).is_empty());
        // Atomics whose protocol needs order need an execution dependency, and no more.
        let in_order = |e: &Event| match e.clone() {
            Event::Access(a) => Event::Access(Access { ordered: true, ..a }),
            other => other,
        };
        let stamps = [in_order(&counted[0]), in_order(&counted[1])];
        assert_eq!(run(&stamps), ["WRITE-AFTER-WRITE"]);
        let order = barrier((FR.0, A::empty()), (FR.0, A::empty()), Memory::None);
        assert!(run(&[stamps[0].clone(), order, stamps[1].clone()]).is_empty());
        let copy = access(S::ALL_TRANSFER, A::TRANSFER_READ, false);
        assert_eq!(
            run(&[counted[0].clone(), copy.clone()]),
            ["READ-AFTER-WRITE"]
        );
        // A read-write access made available through its write bits alone.
        let rw = (FR.0, A::SHADER_STORAGE_WRITE);
        let hand_over = barrier(rw, (S::ALL_TRANSFER, A::TRANSFER_READ), Memory::Buffer(7));
        assert!(run(&[counted[0].clone(), hand_over, copy]).is_empty());
    }

    #[test]
    fn a_write_pending_across_many_barriers_keeps_one_visibility_per_stage_set() {
        let mut t = Tracker::default();
        t.apply(&access(CW.0, CW.1, true), 1);
        for _ in 0..1000 {
            t.apply(&barrier(CW, FR, Memory::Global), 1);
        }
        assert_eq!(t.pending[&7][0].visible.len(), 1);
        assert!(t.apply(&access(FR.0, FR.1, false), 1).is_empty());
    }

    #[test]
    fn reads_of_the_same_stage_collapse_so_pending_stays_small() {
        let mut t = Tracker::default();
        for _ in 0..1000 {
            t.apply(&access(FR.0, FR.1, false), 1);
        }
        assert_eq!(t.pending[&7].len(), 1);
    }
}
