//! Vehicle simulator. (in progress)
