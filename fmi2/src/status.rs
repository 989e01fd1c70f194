//! What a call returns: an fmi2Status, or a refusal that says why.

/// fmi2Status, as a Rust enum.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}

/// A call the instance did not carry out, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    pub status: Status,
    /// Boxed so that a refusal is two words: every call's result then comes back in
    /// registers, not through memory.
    #[allow(clippy::box_collection)] // the point: one word, not three
    pub message: Box<String>,
}

impl Refusal {
    pub fn new(status: Status, message: impl Into<String>) -> Self {
        Refusal {
            status,
            message: Box::new(message.into()),
        }
    }
}

pub type Reply = Result<Status, Refusal>;

/// A refusal with fmi2Error.
pub fn refuse(message: impl Into<String>) -> Refusal {
    Refusal::new(Status::Error, message)
}
