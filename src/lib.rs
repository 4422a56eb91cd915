//! Cross-crate integration tests live in `tests/`; this package has no code of its own.
