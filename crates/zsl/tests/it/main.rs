//! zsl's integration tests, one binary with a module per subject (`cargo test -p zsl --test it
//! udp_sim::` runs one): the UDP clients against the dog simulator, scripted peers and the
//! vendor's captured datagrams; the spline client against the daemon's side on a heap region
//! (`spline_heap`, also run under Miri: `cargo +nightly miri test -p zsl --test it spline_heap::`)
//! and on real shared memory (`spline_sim`); a C program on the spec's packed layout
//! (`c_interop`).

mod c_interop;
mod spline_heap;
mod spline_sim;
mod udp_fixtures;
mod udp_sim;
