//! The live view against viewers: a WebSocket client of our own (always), Foxglove's own client
//! and a headless Chromium on the page (under node, gated like every interop test).

mod feed;
mod foxglove_client;
mod viewer;
