//! Benchmark runner (joins the generator and the diagnosis).
