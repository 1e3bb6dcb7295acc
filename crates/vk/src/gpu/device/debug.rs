//! The validation-layer message log: every WARNING and ERROR message is kept, so a test can fail
//! on it, `--validate` runs can print it and exit non-zero, and `histencil check` can give each
//! case the messages that arrived while it ran (by the log's length before and after).

use ash::vk;
use std::ffi::CStr;
use std::fmt;
use std::sync::Mutex;

/// The message id the canary's call must draw: a buffer of size zero.
pub const CANARY_ID: &str = "VUID-VkBufferCreateInfo-size-00912";

/// One WARNING or ERROR message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ValidationMessage {
    /// `ERROR` or `WARNING`.
    pub severity: &'static str,
    /// The layer's message id name, e.g. `SYNC-HAZARD-WRITE-AFTER-READ`
    /// (`VUID-...` for a valid-usage rule); empty when the layer gives none.
    pub id: String,
    /// The layer's full message.
    pub text: String,
}

impl fmt::Display for ValidationMessage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] {}: {}", self.severity, self.id, self.text)
    }
}

/// Messages the validation layer reported at WARNING or ERROR severity.
#[derive(Default, Debug)]
pub struct ValidationLog {
    messages: Mutex<Vec<ValidationMessage>>,
}

impl ValidationLog {
    /// Every WARNING and ERROR message so far, as text.
    pub fn problems(&self) -> Vec<String> {
        self.lock().iter().map(|m| m.to_string()).collect()
    }

    /// How many messages arrived so far: a mark for [`ValidationLog::since`].
    pub fn len(&self) -> usize {
        self.lock().len()
    }

    /// Whether the layer has said nothing worth failing on.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The messages that arrived after `mark` (a value of [`ValidationLog::len`]).
    pub fn since(&self, mark: usize) -> Vec<ValidationMessage> {
        self.lock().get(mark..).unwrap_or_default().to_vec()
    }

    /// Adds a message of histencil's own (the hazard check's), as the layer's arrive.
    pub(crate) fn push(&self, message: ValidationMessage) {
        self.lock().push(message);
    }

    /// Removes the messages after `mark` that `about` matches and says how many went: for a
    /// call that failed and was retried, whose refusal is reported another way.
    pub(crate) fn forget_since(
        &self,
        mark: usize,
        about: impl Fn(&ValidationMessage) -> bool,
    ) -> usize {
        let mut messages = self.lock();
        let before = messages.len();
        let mut index = 0;
        messages.retain(|m| {
            index += 1;
            index <= mark || !about(m)
        });
        before - messages.len()
    }

    /// Panics with every message when there is any: for tests.
    pub fn assert_clean(&self) {
        let problems = self.problems();
        assert!(
            problems.is_empty(),
            "{} validation message(s):\n{}",
            problems.len(),
            problems.join("\n")
        );
    }

    /// A messenger description (ERROR and WARNING, every message type) that records into `log`:
    /// for an engine that lends histencil its device and wants its messages kept the same way.
    /// Chain it into `VkInstanceCreateInfo` too, to catch messages of instance creation.
    ///
    /// # Safety
    /// The messenger created from it calls back with a pointer to `log`: the caller keeps an
    /// `Arc` of `log` alive until that messenger is destroyed.
    pub unsafe fn messenger_create_info(
        log: &std::sync::Arc<ValidationLog>,
    ) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
        vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(messenger_callback))
            .user_data(std::sync::Arc::as_ptr(log) as *mut std::ffi::c_void)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<ValidationMessage>> {
        // A panic while holding the lock leaves a valid Vec; keep reading it.
        self.messages.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The debug-utils callback. `user_data` points at the context's `ValidationLog`, which outlives
/// the messenger (the context destroys the messenger before dropping its log handle).
///
/// # Safety
/// Called by the Vulkan loader or a layer only, as `PFN_vkDebugUtilsMessengerCallbackEXT`:
/// `data` is null or points at a valid callback-data struct whose `p_message_id_name` and
/// `p_message` are null or NUL-terminated, all for the duration of the call; `user_data` is
/// null or the pointer [`ValidationLog::messenger_create_info`] set, to a `ValidationLog` kept
/// alive (by an `Arc`) until the messenger is destroyed.
pub(crate) unsafe extern "system" fn messenger_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut std::ffi::c_void,
) -> vk::Bool32 {
    let severity = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        "ERROR"
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        "WARNING"
    } else {
        return vk::FALSE;
    };
    if !data.is_null() && !user_data.is_null() {
        // SAFETY: the caller upholds this fn's # Safety: non-null, `data` points at a valid
        // callback-data struct, alive and unchanged for this call; the reference ends with it.
        let data = unsafe { &*data };
        let text = |p: *const std::ffi::c_char| {
            if p.is_null() {
                String::new()
            } else {
                // SAFETY: this fn's # Safety: the struct's non-null strings are NUL-terminated
                // and live for the call; the text is copied out before it returns.
                unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
            }
        };
        // SAFETY: this fn's # Safety: non-null, `user_data` is `Arc::as_ptr` of a live
        // `ValidationLog`, whose `Arc` outlives the messenger. Only a shared reference is made:
        // the log is `Sync` (a `Mutex`), as callbacks may come from several threads at once.
        let log = unsafe { &*(user_data as *const ValidationLog) };
        let id = text(data.p_message_id_name);
        // The canary's deliberate call is the one call the layer is asked to stop (a callback's
        // TRUE makes it return VK_ERROR_VALIDATION_FAILED_EXT instead of passing the call on):
        // no driver ever sees a buffer of size zero from a layer that reports it.
        let abort = id == CANARY_ID;
        log.lock().push(ValidationMessage {
            severity,
            id,
            text: text(data.p_message),
        });
        if abort {
            return vk::TRUE;
        }
    }
    vk::FALSE
}
