//! Pose estimation. (in progress)
