//! The main job: the embedded default scene (see README).
fn main() {}
