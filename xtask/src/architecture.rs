//! `docs/architecture.md` and the README checked against the workspace: the layer table names
//! every crate, once, and nothing else; the README's crate map names every crate and no other.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use anyhow::Context;

/// The workspace's packages, from `cargo metadata`.
pub fn workspace_packages(root: &Path) -> anyhow::Result<BTreeSet<String>> {
    let out = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .args(["metadata", "--no-deps", "--format-version", "1", "--offline"])
        .current_dir(root)
        .output()
        .context("running cargo metadata")?;
    anyhow::ensure!(out.status.success(), "cargo metadata failed: {}", String::from_utf8_lossy(&out.stderr));
    let metadata: serde_json::Value = serde_json::from_slice(&out.stdout).context("cargo metadata's JSON")?;
    let packages = metadata["packages"].as_array().context("no packages in cargo metadata")?;
    Ok(packages.iter().filter_map(|p| p["name"].as_str().map(str::to_owned)).collect())
}

/// The crates the layer table of `architecture.md` lists: the backticked names in the second
/// column of the table under `## The layers`.
pub fn documented_crates(architecture: &str) -> anyhow::Result<Vec<String>> {
    let section = architecture.split("\n## The layers").nth(1).context("no `## The layers` section")?;
    let rows = section.lines().skip_while(|l| !l.starts_with('|')).take_while(|l| l.starts_with('|'));
    let mut crates = Vec::new();
    for row in rows.skip(2) {
        let column = row.split('|').nth(2).with_context(|| format!("a row without a crates column: {row}"))?;
        crates.extend(column.split('`').skip(1).step_by(2).map(str::to_owned));
    }
    anyhow::ensure!(!crates.is_empty(), "the layer table lists no crate");
    Ok(crates)
}

/// The crate-like names of the README's crate map: the words of the first code block under
/// `## The crates`.
pub fn readme_map_words(readme: &str) -> anyhow::Result<BTreeSet<String>> {
    let section = readme.split("\n## The crates\n").nth(1).context("no `## The crates` section")?;
    let block = section.split("```").nth(1).context("no crate map under `## The crates`")?;
    Ok(block
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .filter(|w| !w.is_empty())
        .map(str::to_owned)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layer_table_lists_every_crate_of_the_workspace_once() {
        let root = crate::workspace_root();
        let text = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
        let documented = documented_crates(&text).unwrap();
        let unique: BTreeSet<String> = documented.iter().cloned().collect();
        assert_eq!(unique.len(), documented.len(), "a crate listed twice: {documented:?}");
        let packages = workspace_packages(&root).unwrap();
        let missing: Vec<_> = packages.difference(&unique).collect();
        let unknown: Vec<_> = unique.difference(&packages).collect();
        assert!(missing.is_empty() && unknown.is_empty(), "not in the table: {missing:?}; not crates: {unknown:?}");
    }

    #[test]
    fn the_readme_crate_map_names_every_crate_and_no_other() {
        let root = crate::workspace_root();
        let words = readme_map_words(&std::fs::read_to_string(root.join("README.md")).unwrap()).unwrap();
        let packages = workspace_packages(&root).unwrap();
        let missing: Vec<_> = packages.iter().filter(|p| !words.contains(*p)).collect();
        // Anything that looks like a crate name must be one.
        let crate_like = |w: &&String| w.starts_with("robowire") || w.ends_with("-proto");
        let unknown: Vec<_> = words.iter().filter(crate_like).filter(|w| !packages.contains(*w)).collect();
        assert!(missing.is_empty() && unknown.is_empty(), "not in the map: {missing:?}; not crates: {unknown:?}");
    }

    /// `cargo tree -e normal` of `args`, one package per line.
    fn normal_tree(args: &[&str]) -> String {
        let out = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
            .arg("tree")
            .args(args)
            .args(["-e", "normal", "--prefix", "none", "--offline"])
            .current_dir(crate::workspace_root())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    fn assert_none_of(heavy: &[&str], tree: &str) {
        for heavy in heavy {
            assert!(!tree.lines().any(|l| l.starts_with(&format!("{heavy} v"))), "{heavy} in:\n{tree}");
        }
    }

    #[test]
    fn a_kmc_only_build_of_robowire_devices_links_no_dds_and_no_capture_library() {
        let tree = normal_tree(&["-p", "robowire-devices", "--no-default-features", "--features", "kmc"]);
        assert!(tree.contains("kmc v"), "{tree}");
        assert_none_of(&["rustdds", "robowire-dds", "rtps-proto", "mcap", "zstd", "lz4"], &tree);
    }

    #[test]
    fn cargo_xtask_golden_and_mujoco_build_no_dds_and_no_capture_library() {
        let tree = normal_tree(&["-p", "xtask"]);
        assert!(tree.contains("unitree-proto v"), "{tree}");
        assert_none_of(&["rustdds", "robowire-dds", "unitree", "mcap", "zstd", "lz4"], &tree);
    }

    #[test]
    fn the_table_parser_reads_the_crates_column() {
        let text = "# x\n\n## The layers\n\n| layer | crates | owns |\n|---|---|---|\n| codec | `a`, `b` | bytes |\n| app | `c` | `not-a-crate` |\n\nafter";
        assert_eq!(documented_crates(text).unwrap(), ["a", "b", "c"]);
        assert!(documented_crates("# nothing").is_err());
    }
}
