//! Messages to the host's logger. The host's logger is variadic and runs the message through
//! printf: we always pass the format "%s" and our text as its argument, so a '%' in a message
//! (or in an untrusted category string echoed back) can never be taken for a conversion.

use fmi_sys::fmi2::{fmi2CallbackLogger, fmi2ComponentEnvironment};
use std::ffi::{CStr, CString};

use crate::status::Status;

#[derive(Clone, Copy, Debug)]
pub struct Logger {
    callback: fmi2CallbackLogger,
    environment: fmi2ComponentEnvironment,
}

// The host's environment pointer is opaque to us and only handed back to the host's logger.
unsafe impl Send for Logger {}

fn c_text(text: &str) -> CString {
    CString::new(text.replace('\0', " ")).unwrap_or_default()
}

impl Logger {
    pub fn new(callback: fmi2CallbackLogger, environment: fmi2ComponentEnvironment) -> Self {
        Logger {
            callback,
            environment,
        }
    }

    pub fn log(&self, instance_name: &CStr, status: Status, category: &str, message: &str) {
        if let Some(callback) = self.callback {
            let category = c_text(category);
            let message = c_text(message);
            // SAFETY: the host gave us this callback for this purpose; all strings are
            // NUL-terminated and outlive the call.
            unsafe {
                callback(
                    self.environment,
                    instance_name.as_ptr(),
                    status as u32,
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    message.as_ptr(),
                );
            }
        }
    }
}
