//! The validation-layer message log: every WARNING and ERROR message is kept, so a test can fail
//! on it and `--validate` runs can print it and exit non-zero.

use ash::vk;
use std::ffi::CStr;
use std::sync::Mutex;

/// Messages the validation layer reported at WARNING or ERROR severity.
#[derive(Default, Debug)]
pub struct ValidationLog {
    problems: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Every WARNING and ERROR message so far.
    pub fn problems(&self) -> Vec<String> {
        self.problems.lock().unwrap().clone()
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

    fn record(&self, message: String) {
        self.problems.lock().unwrap().push(message);
    }
}

/// The debug-utils callback. `user_data` points at the context's `ValidationLog`, which outlives the
/// messenger (the context destroys the messenger before dropping its log handle).
pub(crate) unsafe extern "system" fn messenger_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut std::ffi::c_void,
) -> vk::Bool32 {
    let problem = severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
    );
    if problem && !data.is_null() && !user_data.is_null() {
        // SAFETY: the layer passes a valid callback-data struct; user_data is the log (see above).
        let data = unsafe { &*data };
        let text = |p: *const std::ffi::c_char| {
            if p.is_null() {
                String::new()
            } else {
                unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
            }
        };
        let log = unsafe { &*(user_data as *const ValidationLog) };
        log.record(format!(
            "[{severity:?} {kind:?}] {}: {}",
            text(data.p_message_id_name),
            text(data.p_message)
        ));
    }
    vk::FALSE
}
