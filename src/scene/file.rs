//! The scene file format (TOML, serde).
