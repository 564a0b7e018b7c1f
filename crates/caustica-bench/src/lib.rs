//! Nothing but the benches in `benches/`; run them with `cargo bench -p caustica-bench`.
