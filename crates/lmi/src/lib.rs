//! lmi
