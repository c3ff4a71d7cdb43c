//! `docs/architecture.md` and the README checked against the workspace: the layer table names
//! every crate, once, and nothing else; the README's crate map names every crate and no other;
//! every dependency and dev-dependency between the workspace's crates keeps the table's layers
//! ([`layer_violations`]).

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use anyhow::Context;

/// The layer table's row of the tools: apart from the layers' order.
pub const TOOLING: &str = "tooling";
/// The task runner: it may depend on anything, and nothing depends on it.
pub const XTASK: &str = "xtask";
/// The golden files, the interop gate and the peers' environment: any crate's tests may use it (a
/// dev-dependency of anything), so it depends on the lowest layer only (the codecs' tests use it).
pub const FIXTURES: &str = "robowire-fixtures";
/// The facades' layer.
pub const FACADE: &str = "facade";
/// The simulators' layer: beside the facades ("never does: depend on a facade"), above them in
/// the table's order only so that a facade's dev-dependency on its own simulator is the one
/// documented exception ("Facades dev-depend on their own simulator only").
pub const SIMULATORS: &str = "simulators";
/// The one feature through which a crate depends on [`FIXTURES`] outside its dev-dependencies:
/// `robowire-dds`'s `test-support` (its `netns` helper behind the interop gate), which only
/// dev-dependencies may ask for.
pub const TEST_SUPPORT: (&str, &str) = ("robowire-dds", "test-support");

/// `cargo metadata` of the workspace, without its dependencies' packages.
fn metadata(root: &Path) -> anyhow::Result<serde_json::Value> {
    let out = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .args(["metadata", "--no-deps", "--format-version", "1", "--offline"])
        .current_dir(root)
        .output()
        .context("running cargo metadata")?;
    anyhow::ensure!(out.status.success(), "cargo metadata failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).context("cargo metadata's JSON")
}

/// The workspace's packages, from `cargo metadata`.
pub fn workspace_packages(root: &Path) -> anyhow::Result<BTreeSet<String>> {
    package_names(&metadata(root)?)
}

fn package_names(metadata: &serde_json::Value) -> anyhow::Result<BTreeSet<String>> {
    let packages = metadata["packages"].as_array().context("no packages in cargo metadata")?;
    Ok(packages.iter().filter_map(|p| p["name"].as_str().map(str::to_owned)).collect())
}

/// What a dependency is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DependencyKind {
    /// `[dependencies]`: in every build of the crate.
    Normal,
    /// `[dev-dependencies]`: its tests, examples and benches.
    Dev,
    /// `[build-dependencies]`: its build script.
    Build,
}

/// A dependency of one workspace crate on another, as its manifest declares it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dependency {
    /// The crate that depends.
    pub from: String,
    /// The crate depended on.
    pub to: String,
    /// Which table of the manifest.
    pub kind: DependencyKind,
    /// Behind a feature of `from`.
    pub optional: bool,
    /// The features of `to` it asks for.
    pub features: Vec<String>,
    /// Whether it keeps `to`'s default features.
    pub default_features: bool,
}

/// Every dependency between the workspace's crates (a crate on itself, for its tests' features,
/// left out), from `cargo metadata`.
pub fn workspace_dependencies(root: &Path) -> anyhow::Result<Vec<Dependency>> {
    let metadata = metadata(root)?;
    let names = package_names(&metadata)?;
    let mut dependencies = Vec::new();
    for package in metadata["packages"].as_array().context("no packages in cargo metadata")? {
        let from = package["name"].as_str().context("a package without a name")?;
        for d in package["dependencies"].as_array().context("a package without dependencies")? {
            let to = d["name"].as_str().context("a dependency without a name")?;
            if !names.contains(to) || to == from {
                continue;
            }
            let kind = match d["kind"].as_str() {
                None => DependencyKind::Normal,
                Some("dev") => DependencyKind::Dev,
                Some("build") => DependencyKind::Build,
                Some(other) => anyhow::bail!("{from} -> {to}: dependency kind {other:?}"),
            };
            let features = d["features"]
                .as_array()
                .map_or_else(Vec::new, |f| f.iter().filter_map(|f| f.as_str().map(str::to_owned)).collect());
            dependencies.push(Dependency {
                from: from.into(),
                to: to.into(),
                kind,
                optional: d["optional"].as_bool().unwrap_or(false),
                features,
                default_features: d["uses_default_features"].as_bool().unwrap_or(true),
            });
        }
    }
    Ok(dependencies)
}

/// The rows of the layer table under `## The layers`, in its order: each layer's name (first
/// column) and its crates (the backticked names of the second).
pub fn layer_table(architecture: &str) -> anyhow::Result<Vec<(String, Vec<String>)>> {
    let section = architecture.split("\n## The layers").nth(1).context("no `## The layers` section")?;
    let rows = section.lines().skip_while(|l| !l.starts_with('|')).take_while(|l| l.starts_with('|'));
    let mut layers = Vec::new();
    for row in rows.skip(2) {
        let mut columns = row.split('|').skip(1);
        let name = columns.next().map(str::trim).unwrap_or_default();
        let column = columns.next().with_context(|| format!("a row without a crates column: {row}"))?;
        let crates: Vec<String> = column.split('`').skip(1).step_by(2).map(str::to_owned).collect();
        layers.push((name.to_owned(), crates));
    }
    anyhow::ensure!(layers.iter().any(|(_, crates)| !crates.is_empty()), "the layer table lists no crate");
    Ok(layers)
}

/// The crates the layer table of `architecture.md` lists: the backticked names in the second
/// column of the table under `## The layers`.
pub fn documented_crates(architecture: &str) -> anyhow::Result<Vec<String>> {
    Ok(layer_table(architecture)?.into_iter().flat_map(|(_, crates)| crates).collect())
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

/// The layers in the table's order, lowest first (codec, transport, facade, simulators, devices,
/// apps), and the tools apart.
#[derive(Debug, Clone)]
pub struct Layers {
    rows: Vec<(String, Vec<String>)>,
}

impl Layers {
    /// The layers of `architecture.md`'s table.
    pub fn from_architecture(architecture: &str) -> anyhow::Result<Self> {
        let rows = layer_table(architecture)?;
        for needed in [TOOLING, FACADE, SIMULATORS] {
            anyhow::ensure!(rows.iter().any(|(name, _)| name == needed), "the layer table has no `{needed}` row");
        }
        Ok(Self { rows })
    }

    /// `krate`'s layer and its place in the order (0 the lowest; the tools have none).
    fn of(&self, krate: &str) -> Option<(&str, Option<usize>)> {
        let mut rank = 0;
        for (name, crates) in &self.rows {
            let tooling = name == TOOLING;
            if crates.iter().any(|c| c == krate) {
                return Some((name, (!tooling).then_some(rank)));
            }
            rank += usize::from(!tooling);
        }
        None
    }
}

/// The dependencies in `dependencies` that break the layers, each said in one line: no crate
/// depends, not even in its dev-dependencies, on a crate of a higher layer. The documented
/// exceptions, and nothing else:
///
/// - a facade dev-depends on the simulators, without their default features (each facade asks
///   for its own device's feature: "Facades dev-depend on their own simulator only"); the
///   simulators depend on no facade at all (they sit beside the facades);
/// - [`FIXTURES`] is a dev-dependency of any crate; its own dependencies are the lowest layer's;
///   outside dev-dependencies only through [`TEST_SUPPORT`], a feature no normal or build
///   dependency asks for;
/// - [`XTASK`] depends on anything; nothing depends on it.
pub fn layer_violations(layers: &Layers, dependencies: &[Dependency]) -> Vec<String> {
    let mut violations = Vec::new();
    for d in dependencies {
        let kind = match d.kind {
            DependencyKind::Normal => "dependency",
            DependencyKind::Dev => "dev-dependency",
            DependencyKind::Build => "build-dependency",
        };
        let mut broken = |why: String| violations.push(format!("{} -> {} ({kind}): {why}", d.from, d.to));
        if d.from == d.to || d.from == XTASK {
            continue;
        }
        if d.kind != DependencyKind::Dev && d.to == TEST_SUPPORT.0 && d.features.iter().any(|f| f == TEST_SUPPORT.1) {
            broken(format!("`{}` is for tests: only a dev-dependency asks for it", TEST_SUPPORT.1));
        }
        let (Some((from_layer, from_rank)), Some((to_layer, to_rank))) = (layers.of(&d.from), layers.of(&d.to)) else {
            broken("not in the layer table".into());
            continue;
        };
        if d.to == XTASK {
            broken("nothing depends on the task runner".into());
            continue;
        }
        if d.to == FIXTURES {
            let test_support = d.from == TEST_SUPPORT.0 && d.kind == DependencyKind::Normal && d.optional;
            if d.kind != DependencyKind::Dev && !test_support {
                broken(format!("the tests' crate is a dev-dependency (or behind `{}`)", TEST_SUPPORT.1));
            }
            continue;
        }
        let Some(to_rank) = to_rank else {
            broken(format!("{to_layer} ships in no user's build"));
            continue;
        };
        // A tool other than the task runner is used by every layer's tests: it stands lowest.
        let from_rank = from_rank.unwrap_or(0);
        match (from_layer, to_layer) {
            (FACADE, SIMULATORS) if d.kind == DependencyKind::Dev && !d.default_features => {}
            (FACADE, SIMULATORS) if d.kind == DependencyKind::Dev => {
                broken("a facade dev-depends on its own simulator only: default features off".into());
            }
            (SIMULATORS, FACADE) => broken("the simulators sit beside the facades and depend on none".into()),
            _ if to_rank > from_rank => broken(format!("{from_layer} -> {to_layer}, a layer up")),
            _ => {}
        }
    }
    violations
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
    fn every_dependency_and_dev_dependency_keeps_the_layers() {
        let root = crate::workspace_root();
        let text = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
        let layers = Layers::from_architecture(&text).unwrap();
        let dependencies = workspace_dependencies(&root).unwrap();
        assert!(dependencies.len() > 50, "{} dependencies between the crates?", dependencies.len());
        let violations = layer_violations(&layers, &dependencies);
        assert!(violations.is_empty(), "against docs/architecture.md's layers:\n{}", violations.join("\n"));
    }

    /// A table of two layers each side of the facades and the simulators, and the tools.
    const TABLE: &str = "# x\n\n## The layers\n\n| layer | crates | owns |\n|---|---|---|\n\
        | codec | `core`, `proto` | bytes |\n| transport | `dds`, `record` | sockets |\n\
        | facade | `dog` | APIs |\n| simulators | `sim` | devices |\n| devices | `devices` | `open` |\n\
        | apps | `cli` | commands |\n| tooling | `xtask`, `robowire-fixtures` | tests |\n";

    fn dep(from: &str, to: &str, kind: DependencyKind) -> Dependency {
        Dependency {
            from: from.into(),
            to: to.into(),
            kind,
            optional: false,
            features: Vec::new(),
            default_features: true,
        }
    }

    fn violations(dependencies: &[Dependency]) -> Vec<String> {
        layer_violations(&Layers::from_architecture(TABLE).unwrap(), dependencies)
    }

    #[test]
    fn a_dependency_or_dev_dependency_up_a_layer_is_refused() {
        use DependencyKind::{Dev, Normal};
        let down = [dep("dds", "proto", Normal), dep("cli", "sim", Normal), dep("devices", "dog", Normal)];
        let beside = [dep("dds", "record", Dev), dep("core", "proto", Dev), dep("proto", "proto", Dev)];
        assert!(violations(&down).is_empty() && violations(&beside).is_empty());
        assert_eq!(
            violations(&[dep("record", "dog", Dev), dep("record", "sim", Dev), dep("proto", "dds", Normal)]),
            [
                "record -> dog (dev-dependency): transport -> facade, a layer up",
                "record -> sim (dev-dependency): transport -> simulators, a layer up",
                "proto -> dds (dependency): codec -> transport, a layer up",
            ]
        );
        assert_eq!(
            violations(&[dep("cli", "nowhere", Normal)]),
            ["cli -> nowhere (dependency): not in the layer table"]
        );
    }

    #[test]
    fn the_documented_exceptions_and_no_other() {
        use DependencyKind::{Build, Dev, Normal};
        let own_simulator =
            Dependency { default_features: false, features: vec!["dog".into()], ..dep("dog", "sim", Dev) };
        let test_support = Dependency { optional: true, ..dep("robowire-dds", FIXTURES, Normal) };
        let allowed = [
            own_simulator.clone(),
            dep("proto", FIXTURES, Dev),
            dep("cli", FIXTURES, Dev),
            dep(FIXTURES, "proto", Normal),
            dep(XTASK, "cli", Normal),
            dep(XTASK, FIXTURES, Normal),
        ];
        let table = TABLE.replace("`dds`", "`robowire-dds`");
        let layers = Layers::from_architecture(&table).unwrap();
        assert_eq!(layer_violations(&layers, &allowed), Vec::<String>::new());
        assert_eq!(layer_violations(&layers, &[test_support]), Vec::<String>::new());
        let asks = |kind| Dependency { features: vec![TEST_SUPPORT.1.into()], ..dep("cli", "robowire-dds", kind) };
        assert!(layer_violations(&layers, &[asks(Dev)]).is_empty());
        assert_eq!(
            layer_violations(&layers, &[asks(Normal)]),
            ["cli -> robowire-dds (dependency): `test-support` is for tests: only a dev-dependency asks for it"]
        );

        let refused = [
            Dependency { kind: Normal, ..own_simulator.clone() },
            Dependency { default_features: true, ..own_simulator },
            dep("sim", "dog", Dev),
            dep("cli", FIXTURES, Normal),
            dep("dds", FIXTURES, Build),
            dep(FIXTURES, "dds", Normal),
            dep("cli", XTASK, Dev),
        ];
        assert_eq!(
            violations(&refused),
            [
                "dog -> sim (dependency): facade -> simulators, a layer up",
                "dog -> sim (dev-dependency): a facade dev-depends on its own simulator only: default features off",
                "sim -> dog (dev-dependency): the simulators sit beside the facades and depend on none",
                "cli -> robowire-fixtures (dependency): the tests' crate is a dev-dependency (or behind `test-support`)",
                "dds -> robowire-fixtures (build-dependency): the tests' crate is a dev-dependency (or behind `test-support`)",
                "robowire-fixtures -> dds (dependency): tooling -> transport, a layer up",
                "cli -> xtask (dev-dependency): nothing depends on the task runner",
            ]
        );
    }

    #[test]
    fn the_table_parser_reads_the_crates_column() {
        let text = "# x\n\n## The layers\n\n| layer | crates | owns |\n|---|---|---|\n| codec | `a`, `b` | bytes |\n| app | `c` | `not-a-crate` |\n\nafter";
        assert_eq!(documented_crates(text).unwrap(), ["a", "b", "c"]);
        assert_eq!(layer_table(text).unwrap()[1], ("app".to_owned(), vec!["c".to_owned()]));
        assert!(documented_crates("# nothing").is_err());
        assert!(Layers::from_architecture(text).is_err(), "no tooling, facade or simulators row");
    }
}
