//! Job state machine. (in progress)
