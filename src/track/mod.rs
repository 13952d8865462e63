//! Local path and trackers. (in progress)
