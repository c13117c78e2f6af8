//! Ray-traversal acceleration. heron uses Intel Embree through its own FFI layer in
//! [`embree`]; nothing outside that module touches `unsafe`.
pub mod embree;
