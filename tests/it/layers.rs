//! No circular `use` between the modules of one layer (issue 29): in every crate of both
//! workspaces, among the child modules of one parent (the crate root's top-level modules,
//! `design`'s submodules, …), the "refers to" relation has no cycle.
//!
//! How it is checked: every source file is parsed (`syn`), items under `#[cfg(test)]` are
//! dropped (a test may look anywhere), and every path that starts with `crate::`,
//! `super::` or `self::` — in `use` declarations and in code — is resolved to the deepest
//! module it names. A reference from inside sibling A's subtree to inside sibling B's
//! subtree is an edge A → B; references between a module and its ancestors are not
//! edges (a parent declares what its children share). Each parent's sibling graph must
//! be acyclic; a cycle is reported with the files that close it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use quote::ToTokens;

/// A module path from the crate root, e.g. `["design", "current_loop"]`.
type ModPath = Vec<String>;

/// One crate's modules: path → (file, the module paths it refers to).
#[derive(Default)]
struct Crate {
    modules: BTreeMap<ModPath, PathBuf>,
    refs: Vec<(ModPath, ModPath, PathBuf)>,
}

fn has_cfg_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta
                .to_token_stream()
                .to_string()
                .replace(' ', "")
                .contains("cfg(test)")
    })
}

/// The `crate::`/`super::`/`self::` paths in `tokens`, as raw segment lists (the first
/// segment is `crate`, `super` or `self`; a `{…}` group fans out).
fn paths_in(tokens: TokenStream, out: &mut Vec<Vec<String>>) {
    let tts: Vec<TokenTree> = tokens.into_iter().collect();
    let mut i = 0;
    while i < tts.len() {
        match &tts[i] {
            TokenTree::Group(g) => paths_in(g.stream(), out),
            TokenTree::Ident(id) if ["crate", "super", "self"].contains(&id.to_string().as_str()) => {
                // Not a path segment continuing an earlier one (`foo::self`).
                let prev_colon = i >= 1 && matches!(&tts[i - 1], TokenTree::Punct(p) if p.as_char() == ':');
                if !prev_colon {
                    let mut prefix = vec![id.to_string()];
                    i = follow(&tts, i + 1, &mut prefix, out);
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
}

/// Follows `:: seg :: seg …` from `i`; pushes the path(s); returns the index after it.
fn follow(tts: &[TokenTree], mut i: usize, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    loop {
        let colons = matches!(tts.get(i), Some(TokenTree::Punct(p)) if p.as_char() == ':')
            && matches!(tts.get(i + 1), Some(TokenTree::Punct(p)) if p.as_char() == ':');
        if !colons {
            out.push(prefix.clone());
            return i;
        }
        match tts.get(i + 2) {
            Some(TokenTree::Ident(id)) => {
                prefix.push(id.to_string());
                i += 3;
            }
            Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Brace => {
                // `use a::{b, c::d, self}`: each comma-separated item continues the prefix.
                let inner: Vec<TokenTree> = g.stream().into_iter().collect();
                let mut j = 0;
                while j < inner.len() {
                    if let TokenTree::Ident(id) = &inner[j] {
                        let mut p = prefix.clone();
                        if id != "self" {
                            p.push(id.to_string());
                        }
                        j = follow(&inner, j + 1, &mut p, out);
                    }
                    // Skip to after the next top-level comma.
                    while j < inner.len() && !matches!(&inner[j], TokenTree::Punct(p) if p.as_char() == ',') {
                        j += 1;
                    }
                    j += 1;
                }
                return i + 3;
            }
            _ => {
                out.push(prefix.clone());
                return i + 2;
            }
        }
    }
}

/// Reads module `path` from `file` (its items, nested inline modules, and the files of
/// its `mod x;` declarations), recording modules and references.
fn read_module(krate: &mut Crate, path: ModPath, file: &Path, items: Vec<syn::Item>, dir: &Path) {
    krate.modules.insert(path.clone(), file.to_path_buf());
    for item in items {
        let attrs: &[syn::Attribute] = match &item {
            syn::Item::Mod(m) => &m.attrs,
            syn::Item::Use(u) => &u.attrs,
            syn::Item::Fn(f) => &f.attrs,
            syn::Item::Impl(i) => &i.attrs,
            syn::Item::Struct(s) => &s.attrs,
            syn::Item::Enum(e) => &e.attrs,
            syn::Item::Const(c) => &c.attrs,
            syn::Item::Static(s) => &s.attrs,
            syn::Item::Trait(t) => &t.attrs,
            syn::Item::Type(t) => &t.attrs,
            syn::Item::Macro(m) => &m.attrs,
            _ => &[],
        };
        if has_cfg_test(attrs) {
            continue;
        }
        if let syn::Item::Mod(m) = item {
            let mut child = path.clone();
            child.push(m.ident.to_string());
            let child_dir = dir.join(m.ident.to_string());
            match m.content {
                Some((_, inner)) => read_module(krate, child, file, inner, &child_dir),
                None => {
                    let explicit = m.attrs.iter().find_map(|a| {
                        if !a.path().is_ident("path") {
                            return None;
                        }
                        let syn::Meta::NameValue(nv) = &a.meta else { return None };
                        let syn::Expr::Lit(l) = &nv.value else { return None };
                        let syn::Lit::Str(s) = &l.lit else { return None };
                        Some(dir.join(s.value()))
                    });
                    let candidates = [dir.join(format!("{}.rs", m.ident)), child_dir.join("mod.rs")];
                    let Some(f) = explicit.or_else(|| candidates.into_iter().find(|c| c.exists())) else {
                        continue;
                    };
                    let text = std::fs::read_to_string(&f).unwrap();
                    let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
                    read_module(krate, child, &f, parsed.items, &child_dir);
                }
            }
            continue;
        }
        let mut raw = Vec::new();
        paths_in(item.to_token_stream(), &mut raw);
        for segments in raw {
            // Resolve relative to this module.
            let mut base: ModPath = Vec::new();
            let mut rest = segments.as_slice();
            match rest.first().map(String::as_str) {
                Some("crate") => rest = &rest[1..],
                Some("self") => {
                    base = path.clone();
                    rest = &rest[1..];
                }
                Some("super") => {
                    base = path.clone();
                    while rest.first().map(String::as_str) == Some("super") {
                        base.pop();
                        rest = &rest[1..];
                    }
                }
                _ => continue,
            }
            base.extend(rest.iter().cloned());
            krate.refs.push((path.clone(), base, file.to_path_buf()));
        }
    }
}

/// The deepest known module that `target` names (a path into items stops at its module).
fn module_of(krate: &Crate, target: &[String]) -> ModPath {
    let mut m: ModPath = target.to_vec();
    while !m.is_empty() && !krate.modules.contains_key(&m) {
        m.pop();
    }
    m
}

/// Cycles among the children of each parent: `(parent, cycle, files)`.
fn cycles(krate: &Crate) -> Vec<String> {
    // Edges between siblings, with a file that makes each.
    let mut edges: BTreeMap<ModPath, BTreeMap<(String, String), PathBuf>> = BTreeMap::new();
    for (from, to, file) in &krate.refs {
        let to = module_of(krate, to);
        // The common ancestor and the two children of it that contain `from` and `to`.
        let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
        if common == from.len() || common == to.len() {
            continue; // ancestor or descendant
        }
        let parent = from[..common].to_vec();
        edges
            .entry(parent)
            .or_default()
            .entry((from[common].clone(), to[common].clone()))
            .or_insert_with(|| file.clone());
    }
    let mut found = Vec::new();
    for (parent, e) in &edges {
        let nodes: BTreeSet<&String> = e.keys().flat_map(|(a, b)| [a, b]).collect();
        // Depth-first search for a back edge.
        #[derive(Clone, Copy, PartialEq)]
        enum Mark {
            New,
            Open,
            Done,
        }
        let mut mark: BTreeMap<&String, Mark> = nodes.iter().map(|n| (*n, Mark::New)).collect();
        fn dfs<'a>(
            n: &'a String,
            e: &'a BTreeMap<(String, String), PathBuf>,
            mark: &mut BTreeMap<&'a String, Mark>,
            stack: &mut Vec<&'a String>,
            found: &mut Vec<Vec<&'a String>>,
        ) {
            mark.insert(n, Mark::Open);
            stack.push(n);
            for ((_, b), _) in e.iter().filter(|((a, _), _)| a == n) {
                match mark[b] {
                    Mark::New => dfs(b, e, mark, stack, found),
                    Mark::Open => {
                        let k = stack.iter().position(|x| *x == b).unwrap();
                        found.push(stack[k..].to_vec());
                    }
                    Mark::Done => {}
                }
            }
            stack.pop();
            mark.insert(n, Mark::Done);
        }
        let mut cyc = Vec::new();
        for n in &nodes {
            if mark[*n] == Mark::New {
                dfs(n, e, &mut mark, &mut Vec::new(), &mut cyc);
            }
        }
        for c in cyc {
            let mut ring: Vec<String> = c.iter().map(|s| s.to_string()).collect();
            ring.push(c[0].to_string());
            let files: Vec<String> = ring
                .windows(2)
                .map(|w| format!("{} → {}: {}", w[0], w[1], e[&(w[0].clone(), w[1].clone())].display()))
                .collect();
            let at = if parent.is_empty() {
                "crate root".to_string()
            } else {
                parent.join("::")
            };
            found.push(format!("in {at}: {}\n    {}", ring.join(" → "), files.join("\n    ")));
        }
    }
    found
}

/// Every crate's root file (library, binary), both workspaces.
fn crate_roots() -> Vec<PathBuf> {
    let repo = motor_test_support::repo();
    let mut roots = Vec::new();
    for parent in ["crates", "firmware"] {
        let rd = std::fs::read_dir(repo.join(parent)).unwrap();
        let mut dirs: Vec<PathBuf> = rd
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.join("Cargo.toml").exists())
            .collect();
        dirs.sort();
        for d in dirs {
            for root in ["src/lib.rs", "src/main.rs"] {
                if d.join(root).exists() {
                    roots.push(d.join(root));
                }
            }
        }
    }
    roots
}

#[test]
fn no_module_cycles_within_a_layer() {
    let roots = crate_roots();
    assert!(roots.len() >= 10, "found only {} crate roots: {roots:?}", roots.len());
    let mut problems = Vec::new();
    let mut modules = 0;
    for root in &roots {
        let text = std::fs::read_to_string(root).unwrap();
        let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", root.display()));
        let mut krate = Crate::default();
        read_module(&mut krate, Vec::new(), root, parsed.items, root.parent().unwrap());
        modules += krate.modules.len();
        for c in cycles(&krate) {
            problems.push(format!("{}: {c}", root.display()));
        }
    }
    assert!(modules > 100, "only {modules} modules read: the walk missed files");
    assert!(
        problems.is_empty(),
        "{} module cycles:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The checker finds a cycle it is shown (so the test above can fail).
#[test]
fn a_cycle_between_siblings_is_found() {
    let mut k = Crate::default();
    for m in [vec![], vec!["a".to_string()], vec!["b".to_string()]] {
        k.modules.insert(m, PathBuf::from("x.rs"));
    }
    k.refs
        .push((vec!["a".into()], vec!["b".into(), "Item".into()], PathBuf::from("a.rs")));
    assert!(cycles(&k).is_empty(), "one direction is not a cycle");
    k.refs
        .push((vec!["b".into()], vec!["a".into(), "f".into()], PathBuf::from("b.rs")));
    let c = cycles(&k);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(c[0].contains("a → b → a") || c[0].contains("b → a → b"), "{c:?}");
    // A child referring to its parent's items is not a cycle.
    let mut k = Crate::default();
    for m in [vec![], vec!["p".to_string()], vec!["p".to_string(), "c".to_string()]] {
        k.modules.insert(m, PathBuf::from("x.rs"));
    }
    k.refs.push((
        vec!["p".into(), "c".into()],
        vec!["p".into(), "T".into()],
        PathBuf::from("c.rs"),
    ));
    k.refs.push((
        vec!["p".into()],
        vec!["p".into(), "c".into(), "f".into()],
        PathBuf::from("p.rs"),
    ));
    assert!(cycles(&k).is_empty());
}

/// Paths are read from `use` groups and from code.
#[test]
fn paths_are_read_from_groups_and_code() {
    let f: syn::File = syn::parse_quote! {
        use super::{a::X, b, self};
        fn f() { crate::c::d::g(); }
    };
    let mut out = Vec::new();
    for item in f.items {
        paths_in(item.to_token_stream(), &mut out);
    }
    let s: Vec<String> = out.iter().map(|p| p.join("::")).collect();
    assert!(s.contains(&"super::a::X".to_string()), "{s:?}");
    assert!(s.contains(&"super::b".to_string()), "{s:?}");
    assert!(s.contains(&"crate::c::d::g".to_string()), "{s:?}");
}
