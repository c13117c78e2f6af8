//! Helpers shared by the integration tests (each test file includes this module with
//! `mod common;` and uses the parts it needs).
#![allow(dead_code)]

pub mod chi2;
pub mod cli;
pub mod images;
pub mod render;
pub mod scenes;
pub mod serialized;
