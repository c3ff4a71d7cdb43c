//! The built-in page: its files, embedded at build time (no build step, nothing fetched; uPlot,
//! MIT, vendored from npm with its licence).

/// Each file by the path it is served at: its content type and bytes.
const FILES: &[(&str, &str, &str)] = &[
    ("/", "text/html; charset=utf-8", include_str!("../page/index.html")),
    ("/index.html", "text/html; charset=utf-8", include_str!("../page/index.html")),
    ("/live.js", "text/javascript; charset=utf-8", include_str!("../page/live.js")),
    ("/uPlot.iife.min.js", "text/javascript; charset=utf-8", include_str!("../page/uPlot.iife.min.js")),
    ("/uPlot.min.css", "text/css; charset=utf-8", include_str!("../page/uPlot.min.css")),
    ("/uPlot.LICENSE", "text/plain; charset=utf-8", include_str!("../page/uPlot.LICENSE")),
];

/// The file served at `path`: its content type and bytes.
pub(crate) fn file(path: &str) -> Option<(&'static str, &'static [u8])> {
    FILES.iter().find(|(at, ..)| *at == path).map(|(_, content_type, body)| (*content_type, body.as_bytes()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_page_and_what_it_loads_are_served() {
        let (content_type, index) = super::file("/").unwrap();
        assert!(content_type.starts_with("text/html"));
        let index = std::str::from_utf8(index).unwrap();
        for loaded in ["live.js", "uPlot.iife.min.js", "uPlot.min.css"] {
            assert!(index.contains(loaded), "index.html does not load {loaded}");
            assert!(super::file(&format!("/{loaded}")).is_some());
        }
        assert!(super::file("/../Cargo.toml").is_none());
    }
}
