//! The hazard check: every buffer a command reads or writes, and every barrier, journaled as
//! the encoder records them, and held to Vulkan's rule ([`check`]) when histencil submits,
//! across its submissions and frames in flight. A hazard is an ERROR in the validation log
//! (`HISTENCIL-HAZARD-READ-AFTER-WRITE` and its kin, naming both accesses' passes and bindings),
//! so every test that asserts a clean log asserts a hazard-free queue too.
//!
//! Why histencil keeps its own: the buffer hand-overs between its passes (the light passes'
//! split, the tiled classification's rewrite of the tile buffers every slot shares) were held
//! by reading alone. Synchronisation validation passed with each removed, and lavapipe runs
//! commands in order, so no image could show one missing; a GPU that overlaps passes would be
//! the first to. The journal knows what the layer's tracking of descriptors does not always
//! resolve: which buffer each binding of each bound set holds, and whether the shader may
//! write it (`readonly` / `writeonly` in the reflected SPIR-V, [`crate::reflect_bindings`]).
//!
//! What it sees: buffers bound as uniform or storage buffers of sets histencil wrote, vertex
//! and index buffers, indirect arguments, fills, updates and copies; barriers of every kind.
//! What it does not: images (their barriers are derived from declarations, and
//! synchronisation validation tracks their layouts), host access to mapped buffers, an engine's
//! hooks' own sets (written by the engine, not histencil) and command buffers an engine
//! submits itself. It is on for contexts histencil creates in debug builds with validation.

pub(crate) mod check;

use crate::gpu::device::debug::{ValidationLog, ValidationMessage};
use crate::gpu::device::spirv_bindings::{binding_reach, reflect_bindings, Reach, ResourceKind};
use ash::vk;
use ash::vk::Handle;
use ash::vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
use check::{Access, Dependency, Event, Memory, Tracker};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// One binding a pipeline's shaders use: its stage and how.
#[derive(Clone, Copy, Debug)]
struct Binding {
    set: u32,
    binding: u32,
    stage: S,
    read: Option<A>,
    write: Option<A>,
    /// Reached by atomic operations alone.
    atomic: bool,
}

/// What a command buffer has recorded since it was begun, and what is bound in it.
#[derive(Default)]
struct CommandJournal {
    events: Vec<Event>,
    labels: Vec<String>,
    /// The bound pipeline per bind point (graphics 0, compute 1).
    pipelines: [Option<u64>; 2],
    /// The bound sets per bind point, by set index.
    sets: [HashMap<u32, u64>; 2],
    /// The next commands' atomics must run in order ([`Hazards::ordered_atomics`]).
    ordered: bool,
    /// The buffers the open steps declared they write, each with the number of labels open
    /// when it was declared: a label's close drops what was declared inside it.
    declared_writes: Vec<(usize, u64)>,
}

impl CommandJournal {
    /// Journals a plain (not atomic) access of `buffer`.
    fn plain(&mut self, buffer: vk::Buffer, (stage, access): (S, A), write: bool, at: String) {
        self.events.push(Event::Access(Access {
            buffer: buffer.as_raw(),
            stage,
            access,
            write,
            atomic: false,
            ordered: false,
            at,
        }));
    }
}

/// Past this many events a command buffer histencil never submits (an engine's) stops being
/// journaled, so its memory stays bounded.
const MOST_EVENTS: usize = 1 << 20;

#[derive(Default)]
struct Journal {
    buffer_names: HashMap<u64, String>,
    modules: HashMap<u64, Vec<Binding>>,
    pipelines: HashMap<u64, Vec<Binding>>,
    /// (set, binding) -> the buffers it holds.
    sets: HashMap<(u64, u32), Vec<u64>>,
    commands: HashMap<u64, CommandJournal>,
    tracker: Tracker,
    submissions: u64,
    /// Fence -> the submissions it signals for.
    fences: HashMap<u64, Vec<u64>>,
}

/// The hazard check of one context.
pub(crate) struct Hazards {
    journal: Mutex<Journal>,
    log: Arc<ValidationLog>,
}

/// The `n` structures at `p`, none when it is null.
///
/// # Safety
/// `p` is null or points at `n` live values of `T`, alive for `'a`.
unsafe fn parts<'a, T>(p: *const T, n: u32) -> &'a [T] {
    if p.is_null() || n == 0 {
        &[]
    } else {
        // SAFETY: this fn's # Safety.
        unsafe { std::slice::from_raw_parts(p, n as usize) }
    }
}

fn point_index(point: vk::PipelineBindPoint) -> usize {
    usize::from(point == vk::PipelineBindPoint::COMPUTE)
}

impl Hazards {
    pub fn new(log: Arc<ValidationLog>) -> Self {
        Self {
            journal: Mutex::new(Journal::default()),
            log,
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Journal> {
        self.journal.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Keeps a buffer's name for the messages.
    pub fn name(&self, object: vk::ObjectType, raw: u64, name: &str) {
        if object == vk::ObjectType::BUFFER {
            self.lock().buffer_names.insert(raw, name.to_owned());
        }
    }

    /// Reads what a shader module's bindings let it do.
    pub fn module(&self, module: vk::ShaderModule, words: &[u32]) {
        let Ok(reflected) = reflect_bindings(words) else {
            return;
        };
        let reach = binding_reach(words);
        let stage = if reflected.stages.contains(vk::ShaderStageFlags::COMPUTE) {
            S::COMPUTE_SHADER
        } else if reflected.stages.contains(vk::ShaderStageFlags::FRAGMENT) {
            S::FRAGMENT_SHADER
        } else {
            S::VERTEX_SHADER
        };
        let bindings = reflected
            .resources
            .iter()
            .filter_map(|r| {
                let (read, write) = match r.kind {
                    ResourceKind::UniformBuffer => (A::UNIFORM_READ, A::empty()),
                    ResourceKind::StorageBuffer => {
                        (A::SHADER_STORAGE_READ, A::SHADER_STORAGE_WRITE)
                    }
                    _ => return None,
                };
                // What the code does, where it could be read; the declaration otherwise.
                let declared = Reach {
                    loads: r.reads,
                    stores: r.writes,
                    atomics: false,
                };
                let reach = reach.get(&(r.set, r.binding)).copied().unwrap_or(declared);
                let atomic = reach.atomics && !reach.loads && !reach.stores;
                let writes = reach.stores || reach.atomics;
                if !(reach.loads || writes) {
                    return None;
                }
                Some(Binding {
                    set: r.set,
                    binding: r.binding,
                    stage,
                    read: (reach.loads || reach.atomics).then_some(read),
                    write: (writes && !write.is_empty()).then_some(write),
                    atomic,
                })
            })
            .collect();
        self.lock().modules.insert(module.as_raw(), bindings);
    }

    /// A pipeline made of `modules`: it uses what they use.
    pub fn pipeline(&self, pipeline: vk::Pipeline, modules: &[vk::ShaderModule]) {
        let mut journal = self.lock();
        let bindings = modules
            .iter()
            .flat_map(|m| {
                journal
                    .modules
                    .get(&m.as_raw())
                    .cloned()
                    .unwrap_or_default()
            })
            .collect();
        journal.pipelines.insert(pipeline.as_raw(), bindings);
    }

    /// The buffers descriptor writes put in sets.
    pub fn descriptor_writes(&self, writes: &[vk::WriteDescriptorSet]) {
        let mut journal = self.lock();
        for w in writes {
            let buffer = matches!(
                w.descriptor_type,
                vk::DescriptorType::UNIFORM_BUFFER | vk::DescriptorType::STORAGE_BUFFER
            );
            if !buffer || w.p_buffer_info.is_null() {
                continue;
            }
            // SAFETY: a write of a buffer type points at `descriptor_count` buffer infos
            // (VUID-VkWriteDescriptorSet-descriptorType-00324), alive for the update call this
            // journals.
            let infos =
                unsafe { std::slice::from_raw_parts(w.p_buffer_info, w.descriptor_count as usize) };
            let buffers = infos.iter().map(|i| i.buffer.as_raw()).collect();
            journal
                .sets
                .insert((w.dst_set.as_raw(), w.dst_binding), buffers);
        }
    }

    /// A buffer destroyed: its handle may name another buffer next.
    pub fn forget_buffer(&self, buffer: vk::Buffer) {
        let mut journal = self.lock();
        journal.tracker.forget(buffer.as_raw());
        journal.buffer_names.remove(&buffer.as_raw());
    }

    /// `cmd` was begun: what it held before is gone.
    pub fn begun(&self, cmd: vk::CommandBuffer) {
        self.lock().commands.remove(&cmd.as_raw());
    }

    fn with(&self, cmd: vk::CommandBuffer, f: impl FnOnce(&mut CommandJournal, &Journal)) {
        let mut guard = self.lock();
        let journal = &mut *guard;
        let mut command = journal.commands.remove(&cmd.as_raw()).unwrap_or_default();
        if command.events.len() < MOST_EVENTS {
            f(&mut command, journal);
        }
        journal.commands.insert(cmd.as_raw(), command);
    }

    pub fn label(&self, cmd: vk::CommandBuffer, open: Option<&str>) {
        self.with(cmd, |c, _| match open {
            Some(name) => c.labels.push(name.to_owned()),
            None => {
                c.labels.pop();
                let open = c.labels.len();
                c.declared_writes.retain(|(depth, _)| *depth <= open);
            }
        });
    }

    /// The buffers the step being recorded declares it writes (`Recording::declare_buffers`):
    /// what its shaders may write, until the innermost open label closes.
    pub fn declare_writes(&self, cmd: vk::CommandBuffer, buffers: &[vk::Buffer]) {
        self.with(cmd, |c, _| {
            let depth = c.labels.len();
            c.declared_writes
                .extend(buffers.iter().map(|b| (depth, b.as_raw())));
        });
    }

    pub fn ordered_atomics(&self, cmd: vk::CommandBuffer, ordered: bool) {
        self.with(cmd, |c, _| c.ordered = ordered);
    }

    pub fn bind_pipeline(
        &self,
        cmd: vk::CommandBuffer,
        point: vk::PipelineBindPoint,
        pipeline: vk::Pipeline,
    ) {
        self.with(cmd, |c, _| {
            c.pipelines[point_index(point)] = Some(pipeline.as_raw());
        });
    }

    pub fn bind_sets(
        &self,
        cmd: vk::CommandBuffer,
        point: vk::PipelineBindPoint,
        first: u32,
        sets: &[vk::DescriptorSet],
    ) {
        self.with(cmd, |c, _| {
            for (i, set) in sets.iter().enumerate() {
                c.sets[point_index(point)].insert(first + i as u32, set.as_raw());
            }
        });
    }

    /// A draw or dispatch: every buffer its pipeline's shaders may read or write through the
    /// bound sets, and `extra` (vertex, index, indirect buffers: buffer, stage, access).
    pub fn shade(
        &self,
        cmd: vk::CommandBuffer,
        point: vk::PipelineBindPoint,
        extra: &[(vk::Buffer, S, A)],
    ) {
        let mut undeclared = Vec::new();
        self.with(cmd, |c, journal| {
            let at = c.labels.join("/");
            for &(buffer, stage, access) in extra {
                c.plain(buffer, (stage, access), false, at.clone());
            }
            let i = point_index(point);
            let Some(bindings) = c.pipelines[i].and_then(|p| journal.pipelines.get(&p)) else {
                return;
            };
            for b in bindings {
                let Some(set) = c.sets[i].get(&b.set) else {
                    continue;
                };
                let Some(buffers) = journal.sets.get(&(*set, b.binding)) else {
                    continue;
                };
                let at = format!("{at}: set {} binding {}", b.set, b.binding);
                for &buffer in buffers {
                    // A read-write binding is one access that writes: what a later access
                    // conflicts with either way.
                    let (access, write) = match (b.read, b.write) {
                        (r, Some(w)) => (r.unwrap_or(A::empty()) | w, true),
                        (Some(r), None) => (r, false),
                        (None, None) => continue,
                    };
                    if write && !c.declared_writes.iter().any(|(_, d)| *d == buffer) {
                        let name = journal.buffer_names.get(&buffer).cloned();
                        undeclared.push(format!(
                            "{at} writes buffer `{}`, which its pass did not declare \
                             (`Recording::declare_buffers`): its barriers cannot be derived",
                            name.unwrap_or_else(|| format!("{buffer:#x}"))
                        ));
                    }
                    c.events.push(Event::Access(Access {
                        buffer,
                        stage: b.stage,
                        access,
                        write,
                        atomic: b.atomic,
                        ordered: b.atomic && c.ordered,
                        at: at.clone(),
                    }));
                }
            }
        });
        for text in undeclared {
            self.log.push(ValidationMessage {
                severity: "ERROR",
                id: "HISTENCIL-UNDECLARED-WRITE".into(),
                text,
            });
        }
    }

    /// A read of `buffer` at a (stage, access) outside a draw's sets: a bound vertex buffer.
    pub fn read(&self, cmd: vk::CommandBuffer, buffer: vk::Buffer, (stage, access): (S, A)) {
        self.with(cmd, |c, _| {
            let at = format!("{}: vertex buffer", c.labels.join("/"));
            c.plain(buffer, (stage, access), false, at);
        });
    }

    /// A transfer command: `reads` read, `writes` written.
    pub fn transfer(
        &self,
        cmd: vk::CommandBuffer,
        what: &str,
        reads: &[vk::Buffer],
        writes: &[vk::Buffer],
    ) {
        self.with(cmd, |c, _| {
            let at = format!("{}: {what}", c.labels.join("/"));
            for buffer in reads {
                c.plain(
                    *buffer,
                    (S::ALL_TRANSFER, A::TRANSFER_READ),
                    false,
                    at.clone(),
                );
            }
            for buffer in writes {
                c.plain(
                    *buffer,
                    (S::ALL_TRANSFER, A::TRANSFER_WRITE),
                    true,
                    at.clone(),
                );
            }
        });
    }

    /// A barrier command.
    pub fn barrier(&self, cmd: vk::CommandBuffer, dependency: &vk::DependencyInfo) {
        // SAFETY: `dependency` is a valid `VkDependencyInfo` about to be recorded: each
        // pointer is null or points at its count of barriers.
        let (memory, buffers, images) = unsafe {
            (
                parts(
                    dependency.p_memory_barriers,
                    dependency.memory_barrier_count,
                ),
                parts(
                    dependency.p_buffer_memory_barriers,
                    dependency.buffer_memory_barrier_count,
                ),
                parts(
                    dependency.p_image_memory_barriers,
                    dependency.image_memory_barrier_count,
                ),
            )
        };
        let mut all: Vec<Dependency> = memory
            .iter()
            .map(|m| Dependency {
                src: (m.src_stage_mask, m.src_access_mask),
                dst: (m.dst_stage_mask, m.dst_access_mask),
                memory: Memory::Global,
            })
            .collect();
        all.extend(buffers.iter().map(|b| Dependency {
            src: (b.src_stage_mask, b.src_access_mask),
            dst: (b.dst_stage_mask, b.dst_access_mask),
            memory: Memory::Buffer(b.buffer.as_raw()),
        }));
        all.extend(images.iter().map(|b| Dependency {
            src: (b.src_stage_mask, b.src_access_mask),
            dst: (b.dst_stage_mask, b.dst_access_mask),
            memory: Memory::None,
        }));
        self.with(cmd, |c, _| c.events.push(Event::Barrier(all)));
    }

    /// `cmds` submitted in this order, signalling `fence`: their journals are checked against
    /// what the queue holds, and each hazard goes to the validation log.
    pub fn submitted(&self, cmds: &[vk::CommandBuffer], fence: vk::Fence) {
        let mut guard = self.lock();
        let journal = &mut *guard;
        journal.submissions += 1;
        let submission = journal.submissions;
        if fence != vk::Fence::null() {
            let waiting = journal.fences.entry(fence.as_raw()).or_default();
            waiting.push(submission);
        }
        let mut found = Vec::new();
        for cmd in cmds {
            let Some(command) = journal.commands.remove(&cmd.as_raw()) else {
                continue;
            };
            for event in &command.events {
                found.extend(journal.tracker.apply(event, submission));
            }
        }
        let name = |b: u64| {
            journal
                .buffer_names
                .get(&b)
                .cloned()
                .unwrap_or_else(|| format!("{b:#x}"))
        };
        for hazard in found {
            let text = format!(
                "buffer `{}`: {} ({:?}, {:?}) then {} ({:?}, {:?}) with no dependency between \
                 that orders them{}",
                name(hazard.later.buffer),
                hazard.earlier.at,
                hazard.earlier.stage,
                hazard.earlier.access,
                hazard.later.at,
                hazard.later.stage,
                hazard.later.access,
                if hazard.earlier.write {
                    " and makes the write visible"
                } else {
                    ""
                },
            );
            self.log.push(ValidationMessage {
                severity: "ERROR",
                id: format!("HISTENCIL-HAZARD-{}", hazard.kind),
                text,
            });
        }
    }

    /// The host saw `fence` signalled: its submissions are complete.
    pub fn waited(&self, fence: vk::Fence) {
        let mut journal = self.lock();
        if let Some(done) = journal.fences.remove(&fence.as_raw()) {
            journal.tracker.complete(&done);
        }
    }

    /// The device is idle.
    pub fn idle(&self) {
        let mut journal = self.lock();
        journal.tracker.clear();
        journal.fences.clear();
    }
}

/// A buffer hand-over of histencil's that a hazard test leaves out, to prove the check finds
/// it missing (`tests/tests/hazards.rs`). Not for engines: leaving one out records a frame with
/// a data race.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandOver {
    /// The light passes' split before a statistics draw, which orders the counted draws.
    LightSplit,
    /// The tiled classification's rewrite of the tile buffers every slot shares, after every
    /// earlier use of them (another slot's frame, the depth-id passes).
    TileRewrite,
    /// The tile buffers the classification wrote, handed to the light lists and the shade.
    TileLists,
    /// Not a hand-over but what barriers are derived from: the classification's declaration
    /// of the tile buffers its shader writes.
    ClassifyDeclaration,
}

thread_local! {
    static OMITTED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// While the returned guard lives, this thread's recordings leave `hand_over` out.
#[doc(hidden)]
pub fn omit_hand_over(hand_over: HandOver) -> Omitted {
    let bit = 1 << hand_over as u32;
    OMITTED.with(|o| o.set(o.get() | bit));
    Omitted(bit)
}

/// Puts the hand-over back when dropped.
#[doc(hidden)]
pub struct Omitted(u32);

impl Drop for Omitted {
    fn drop(&mut self) {
        OMITTED.with(|o| o.set(o.get() & !self.0));
    }
}

/// Whether a recording on this thread records `hand_over` (always, but in a hazard test).
pub(crate) fn records(hand_over: HandOver) -> bool {
    OMITTED.with(|o| o.get() & (1 << hand_over as u32) == 0)
}
