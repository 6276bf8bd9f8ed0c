//! `cargo xtask circles`: no module circles in any crate (also the first
//! step of `cargo xtask test`; docs/architecture.md, "Module circles").
//!
//! Each file is a module. An edge A -> B is a `crate::` or `super::` path
//! in A's file, in a `use` or in code, that names module B or something
//! inside it; a module also answers for its children's edges to modules
//! outside it (not for their `super::` paths). A circle is a cycle of
//! edges. The scan is lexical:
//!
//! - comments, strings and character literals are blanked first;
//! - items under `#[cfg(test)]` (and a file under `#![cfg(test)]`, or
//!   declared by a `#[cfg(test)] mod x;`) are skipped;
//! - a path (each leaf of a `use` tree) resolves to the longest module
//!   file that prefixes it, `super` counted from the inline module it is
//!   written in; a path into the file itself is no edge;
//! - a parent's `mod x;` and its plain `x::…` or `self::…` paths are no
//!   edges: only `crate::` and `super::` paths are;
//! - a crate's roots (`lib.rs`, `main.rs`, `bin/*.rs`) are separate trees,
//!   each followed through its `mod` declarations.

use crate::util::{root, Result};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::Path;

/// Checks every crate of the workspace (`crates/*` and `xtask`).
pub fn run() -> Result {
    let root = root();
    let mut dirs: Vec<_> = std::fs::read_dir(root.join("crates"))
        .map_err(|e| format!("cannot list crates/: {e}"))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.join("src").is_dir())
        .collect();
    dirs.push(root.join("xtask"));
    dirs.sort();
    let mut failures = Vec::new();
    let mut modules = 0;
    for dir in &dirs {
        let name = dir.file_name().unwrap_or_default().to_string_lossy();
        let files = read_tree(&dir.join("src"))?;
        let (count, found) = check(&name, &files);
        modules += count;
        failures.extend(found);
    }
    if failures.is_empty() {
        println!("circles: none in {modules} modules");
        Ok(())
    } else {
        Err(format!(
            "module circles (break each by moving the item both modules \
             need down to where it belongs; docs/architecture.md, \
             \"Module circles\"):\n  {}",
            failures.join("\n  ")
        ))
    }
}

/// Checks the crate `name` whose `src/` holds `files`: its number of
/// modules, and each circle in words.
fn check(name: &str, files: &BTreeMap<String, String>) -> (usize, Vec<String>) {
    let mut graph = Graph::build(files);
    graph.lift();
    let failures = graph
        .circles()
        .iter()
        .map(|c| format!("{name}: {c}"))
        .collect();
    (graph.names.len(), failures)
}

/// Every `.rs` file under `src`, by its path relative to `src` with `/`.
fn read_tree(src: &Path) -> Result<BTreeMap<String, String>> {
    let mut files = BTreeMap::new();
    let mut dirs = vec![src.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        let entries =
            std::fs::read_dir(&dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
        for entry in entries {
            let path = entry
                .map_err(|e| format!("cannot list {}: {e}", dir.display()))?
                .path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path)
                    .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
                let rel = path.strip_prefix(src).unwrap_or(&path);
                let rel = rel.to_string_lossy().replace('\\', "/");
                files.insert(rel, text);
            }
        }
    }
    Ok(files)
}

/// One strongly connected set of modules, with one cycle through it.
#[derive(Debug)]
struct Circle {
    /// The modules, sorted.
    members: Vec<String>,
    /// `a -> b -> a`, the shortest cycle from the first member, a lifted
    /// edge followed by the child it stands for (`a (by a::c) -> b`).
    spelled: String,
}

impl std::fmt::Display for Circle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.spelled)?;
        if self.members.len() > self.spelled.matches(" -> ").count() {
            write!(f, "; all in one circle: {}", self.members.join(", "))?;
        }
        Ok(())
    }
}

/// The module graph of one crate.
#[derive(Default)]
struct Graph {
    /// Module names (`crate`, `a::b`; `main.rs`, `main.rs: a` in another
    /// root's tree).
    names: Vec<String>,
    /// Each module's tree and path, by module.
    modules: Vec<Module>,
    /// Edges by module, deduplicated.
    edges: Vec<BTreeSet<usize>>,
    /// The child whose path a lifted edge stands for, by edge.
    via: BTreeMap<(usize, usize), usize>,
}

/// A module file found from a root.
#[derive(Clone)]
struct Module {
    /// Its tree (the root's index) and path inside it.
    tree: usize,
    path: Vec<String>,
}

impl Graph {
    /// The graph of a crate's `src/` files (path relative to `src/`).
    fn build(files: &BTreeMap<String, String>) -> Graph {
        let roots: Vec<&String> = files
            .keys()
            .filter(|f| {
                *f == "lib.rs"
                    || *f == "main.rs"
                    || (f.starts_with("bin/") && f.matches('/').count() == 1)
            })
            .collect();
        // Walk each root's `mod` declarations; scan each file once.
        let mut modules: Vec<Module> = Vec::new();
        let mut scans: Vec<Scan> = Vec::new();
        for (tree, root) in roots.iter().enumerate() {
            let mut queue = VecDeque::from([(root.to_string(), Vec::new())]);
            while let Some((file, path)) = queue.pop_front() {
                let scan = scan(&files[&file]);
                if scan.test_only {
                    continue;
                }
                let dir = match file.strip_suffix(".rs") {
                    Some(stem) if file == **root && !stem.starts_with("bin/") => String::new(),
                    Some(_) if file == "mod.rs" || file.ends_with("/mod.rs") => {
                        file[..file.len() - "mod.rs".len()].to_string()
                    }
                    Some(stem) => format!("{stem}/"),
                    None => String::new(),
                };
                for child in &scan.children {
                    let base = format!("{dir}{}", child.join("/"));
                    for candidate in [format!("{base}.rs"), format!("{base}/mod.rs")] {
                        if files.contains_key(&candidate) {
                            let mut child_path = path.clone();
                            child_path.extend(child.iter().cloned());
                            queue.push_back((candidate, child_path));
                            break;
                        }
                    }
                }
                modules.push(Module { tree, path });
                scans.push(scan);
            }
        }
        let index: BTreeMap<(usize, &[String]), usize> = modules
            .iter()
            .enumerate()
            .map(|(i, m)| ((m.tree, m.path.as_slice()), i))
            .collect();
        let mut graph = Graph::default();
        for m in &modules {
            // The library's tree, or a lone binary's, reads plainly.
            let root = roots[m.tree].as_str();
            let plain = root == "lib.rs" || (root == "main.rs" && !files.contains_key("lib.rs"));
            let tree = if plain {
                String::new()
            } else {
                root.to_string()
            };
            graph
                .names
                .push(match (tree.is_empty(), m.path.is_empty()) {
                    (true, true) => "crate".to_string(),
                    (true, false) => m.path.join("::"),
                    (false, true) => tree,
                    (false, false) => format!("{tree}: {}", m.path.join("::")),
                });
        }
        for (from, (m, scan)) in modules.iter().zip(&scans).enumerate() {
            let mut targets = BTreeSet::new();
            for (inline, path) in &scan.paths {
                let Some(full) = absolute(&m.path, inline, path) else {
                    continue;
                };
                let to = (0..=full.len())
                    .rev()
                    .find_map(|n| index.get(&(m.tree, &full[..n])).copied());
                if let Some(to) = to.filter(|&to| to != from) {
                    targets.insert(to);
                }
            }
            graph.edges.push(targets);
        }
        graph.modules = modules;
        graph
    }

    /// Makes each module answer for its children: a child's edge to a
    /// module outside its parent (and not above it) is the parent's too,
    /// and so on up. A child's `super::` paths stay its own.
    fn lift(&mut self) {
        let index: BTreeMap<(usize, &[String]), usize> = self
            .modules
            .iter()
            .enumerate()
            .map(|(i, m)| ((m.tree, m.path.as_slice()), i))
            .collect();
        let mut lifted = self.edges.clone();
        for (from, targets) in self.edges.iter().enumerate() {
            let m = &self.modules[from];
            for &to in targets {
                let target = &self.modules[to].path;
                for ancestor in (1..m.path.len()).map(|n| &m.path[..n]) {
                    let related = target.starts_with(ancestor) || ancestor.starts_with(target);
                    match index.get(&(m.tree, ancestor)) {
                        Some(&a) if !related && lifted[a].insert(to) => {
                            self.via.insert((a, to), from);
                        }
                        _ => {}
                    }
                }
            }
        }
        self.edges = lifted;
    }

    /// The strongly connected sets of more than one module (Tarjan), each
    /// spelled as its shortest cycle from its first member.
    fn circles(&self) -> Vec<Circle> {
        let sets = strongly_connected(&self.edges);
        let mut circles: Vec<Circle> = sets
            .into_iter()
            .filter(|set| set.len() > 1)
            .map(|set| {
                let mut members: Vec<String> = set.iter().map(|&i| self.names[i].clone()).collect();
                members.sort();
                let start = set
                    .iter()
                    .copied()
                    .min_by_key(|&i| &self.names[i])
                    .unwrap_or_default();
                let cycle = self.shortest_cycle(start, &set);
                let mut spelled = self.names[start].clone();
                for pair in cycle.windows(2) {
                    if let Some(&child) = self.via.get(&(pair[0], pair[1])) {
                        spelled += &format!(" (by {})", self.names[child]);
                    }
                    spelled += &format!(" -> {}", self.names[pair[1]]);
                }
                Circle { members, spelled }
            })
            .collect();
        circles.sort_by(|a, b| a.members.cmp(&b.members));
        circles
    }

    /// A shortest path from `start` back to itself inside `set` (breadth
    /// first), both ends included.
    fn shortest_cycle(&self, start: usize, set: &BTreeSet<usize>) -> Vec<usize> {
        let mut came_from: BTreeMap<usize, usize> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        while let Some(at) = queue.pop_front() {
            for &next in &self.edges[at] {
                if !set.contains(&next) || came_from.contains_key(&next) {
                    continue;
                }
                came_from.insert(next, at);
                if next == start {
                    let mut cycle = vec![start];
                    let mut back = at;
                    while back != start {
                        cycle.push(back);
                        back = came_from[&back];
                    }
                    cycle.push(start);
                    cycle.reverse();
                    return cycle;
                }
                queue.push_back(next);
            }
        }
        vec![start]
    }
}

/// Tarjan's strongly connected components of a graph given by adjacency.
fn strongly_connected(edges: &[BTreeSet<usize>]) -> Vec<BTreeSet<usize>> {
    struct State<'a> {
        edges: &'a [BTreeSet<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<BTreeSet<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in s.edges[v].iter() {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut set = BTreeSet::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                set.insert(w);
                if w == v {
                    break;
                }
            }
            s.out.push(set);
        }
    }
    let n = edges.len();
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The module path a `crate::`/`super::` path names, from the file module
/// `file` and the inline modules `inline` it is written in; `None` when
/// `super` climbs above the crate.
fn absolute(file: &[String], inline: &[String], path: &[String]) -> Option<Vec<String>> {
    let mut segments = path.iter();
    let mut base: Vec<String> = file.iter().chain(inline).cloned().collect();
    let mut rest: Vec<String> = Vec::new();
    let first = segments.next()?;
    if first == "crate" {
        base.clear();
    } else {
        base.pop()?;
    }
    for segment in segments {
        if segment == "super" && rest.is_empty() {
            base.pop()?;
        } else if segment != "self" {
            rest.push(segment.clone());
        }
    }
    base.extend(rest);
    Some(base)
}

/// What the scan of one file finds.
#[derive(Debug, Default, PartialEq)]
struct Scan {
    /// `#![cfg(test)]` at its top.
    test_only: bool,
    /// Its `mod x;` declarations (inside inline modules: `a`, `x`).
    children: Vec<Vec<String>>,
    /// Its `crate::`/`super::` paths: the inline modules each is written
    /// in, and the path's segments (`super`, `a`, `B`).
    paths: Vec<(Vec<String>, Vec<String>)>,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Ident(String),
    /// `::`
    Colons,
    Punct(char),
}

/// Scans one file's text.
fn scan(text: &str) -> Scan {
    let tokens = tokenize(text);
    let mut out = Scan::default();
    // Inline modules open around the cursor: name, brace depth inside.
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            Token::Punct('#') => {
                let inner = tokens.get(i + 1) == Some(&Token::Punct('!'));
                let open = if inner { i + 2 } else { i + 1 };
                let Some(end) = closing(&tokens, open) else {
                    i += 1;
                    continue;
                };
                if is_cfg_test(&tokens[open..=end]) {
                    if inner && depth == 0 {
                        out.test_only = true;
                        return out;
                    }
                    if inner {
                        // The whole inline module is test code: skip to
                        // its closing brace.
                        i = skip_to_depth(&tokens, end + 1, depth);
                        continue;
                    }
                    i = skip_item(&tokens, end + 1);
                    continue;
                }
                i = end + 1;
                continue;
            }
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                depth = depth.saturating_sub(1);
                if inline.last().is_some_and(|(_, d)| *d > depth) {
                    inline.pop();
                }
            }
            Token::Ident(word) if word == "mod" => {
                if let Some(Token::Ident(name)) = tokens.get(i + 1) {
                    match tokens.get(i + 2) {
                        Some(Token::Punct(';')) => {
                            let mut child: Vec<String> =
                                inline.iter().map(|(n, _)| n.clone()).collect();
                            child.push(name.clone());
                            out.children.push(child);
                            i += 3;
                            continue;
                        }
                        Some(Token::Punct('{')) => {
                            depth += 1;
                            inline.push((name.clone(), depth));
                            i += 3;
                            continue;
                        }
                        _ => {}
                    }
                }
            }
            Token::Ident(word) if word == "crate" || word == "super" => {
                let after_colons = i > 0 && tokens[i - 1] == Token::Colons;
                let after_in = i > 0 && tokens[i - 1] == Token::Ident("in".to_string());
                if !after_colons && !after_in && tokens.get(i + 1) == Some(&Token::Colons) {
                    let (paths, next) = use_tree(&tokens, i + 1, vec![word.clone()]);
                    let here: Vec<String> = inline.iter().map(|(n, _)| n.clone()).collect();
                    out.paths
                        .extend(paths.into_iter().map(|p| (here.clone(), p)));
                    i = next;
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// The paths of a path or `use` tree whose `prefix` is read and whose next
/// token, at `i`, may be `::`; and the index after it.
fn use_tree(tokens: &[Token], mut i: usize, mut prefix: Vec<String>) -> (Vec<Vec<String>>, usize) {
    while tokens.get(i) == Some(&Token::Colons) {
        match tokens.get(i + 1) {
            Some(Token::Ident(segment)) => {
                prefix.push(segment.clone());
                i += 2;
            }
            Some(Token::Punct('{')) => {
                let mut paths = Vec::new();
                i += 2;
                loop {
                    match tokens.get(i) {
                        Some(Token::Punct('}')) | None => return (paths, i + 1),
                        Some(Token::Punct(',')) => i += 1,
                        Some(Token::Ident(segment)) => {
                            let mut inner = prefix.clone();
                            if segment != "self" {
                                inner.push(segment.clone());
                            }
                            let (more, next) = use_tree(tokens, i + 1, inner);
                            paths.extend(more);
                            i = next;
                            // `as name`
                            if tokens.get(i) == Some(&Token::Ident("as".to_string())) {
                                i += 2;
                            }
                        }
                        Some(_) => {
                            // `*`, or anything unexpected: the prefix.
                            paths.push(prefix.clone());
                            i += 1;
                        }
                    }
                }
            }
            _ => break, // `::*`, `::<T>`
        }
    }
    (vec![prefix], i)
}

/// Whether an attribute's tokens (`[` … `]`) are `[cfg(test)]`.
fn is_cfg_test(attribute: &[Token]) -> bool {
    let cfg_test = [
        Token::Punct('['),
        Token::Ident("cfg".to_string()),
        Token::Punct('('),
        Token::Ident("test".to_string()),
        Token::Punct(')'),
        Token::Punct(']'),
    ];
    attribute == cfg_test
}

/// The index of the bracket closing the one opened at `open`.
fn closing(tokens: &[Token], open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, token) in tokens.iter().enumerate().skip(open) {
        match token {
            Token::Punct('(' | '[' | '{') => depth += 1,
            Token::Punct(')' | ']' | '}') => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(i);
                }
            }
            _ => {}
        }
        if depth == 0 {
            return None;
        }
    }
    None
}

/// The index after the item starting at `i` (its further attributes
/// included): after its `;` or its closing `}` at its own level, or after
/// its `,` when it is a field, variant or argument (not an item that may
/// have generics).
fn skip_item(tokens: &[Token], mut i: usize) -> usize {
    let mut depth = 0usize;
    let mut first = i;
    while tokens.get(first) == Some(&Token::Punct('#')) {
        first = closing(tokens, first + 1).map_or(first + 1, |end| end + 1);
    }
    if tokens.get(first) == Some(&Token::Ident("pub".to_string())) {
        first += 1;
        if tokens.get(first) == Some(&Token::Punct('(')) {
            first = closing(tokens, first).map_or(first, |end| end + 1);
        }
    }
    let generic = [
        "fn", "impl", "struct", "enum", "trait", "type", "union", "unsafe",
    ];
    let comma_ends =
        !matches!(tokens.get(first), Some(Token::Ident(w)) if generic.contains(&w.as_str()));
    while i < tokens.len() {
        match tokens[i] {
            Token::Punct('(' | '[' | '{') => depth += 1,
            Token::Punct(c @ (')' | ']' | '}')) => {
                if depth == 0 {
                    return i; // the enclosing block ends: so does the item
                }
                depth -= 1;
                if depth == 0 && c == '}' {
                    return i + 1;
                }
            }
            Token::Punct(';') if depth == 0 => return i + 1,
            Token::Punct(',') if depth == 0 && comma_ends => return i + 1,
            _ => {}
        }
        i += 1;
    }
    i
}

/// The index of the `}` that closes the block the cursor is in at brace
/// depth `depth` (its own depth becoming `depth - 1`).
fn skip_to_depth(tokens: &[Token], mut i: usize, depth: usize) -> usize {
    let mut level = depth;
    while i < tokens.len() {
        match tokens[i] {
            Token::Punct('{') => level += 1,
            Token::Punct('}') => {
                if level == depth {
                    return i;
                }
                level -= 1;
            }
            _ => {}
        }
        i += 1;
    }
    i
}

/// Identifiers, `::` and single punctuation characters of Rust source;
/// comments, string, byte-string, raw-string and character literals and
/// lifetimes' quotes left out.
fn tokenize(text: &str) -> Vec<Token> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    let at = |i: usize| chars.get(i).copied().unwrap_or('\0');
    while i < chars.len() {
        let c = chars[i];
        if c == '/' && at(i + 1) == '/' {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && at(i + 1) == '*' {
            let mut nesting = 0;
            while i < chars.len() {
                if chars[i] == '/' && at(i + 1) == '*' {
                    nesting += 1;
                    i += 2;
                } else if chars[i] == '*' && at(i + 1) == '/' {
                    nesting -= 1;
                    i += 2;
                    if nesting == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == '"' {
            i = skip_string(&chars, i + 1);
        } else if c == '\'' {
            if at(i + 1) == '\\' {
                // '\n', '\u{..}', '\''
                i += 3;
                while i < chars.len() && chars[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(i + 2) == '\'' {
                i += 3; // 'a'
            } else {
                i += 1; // a lifetime: its name follows as an identifier
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect();
            let raw = matches!(word.as_str(), "r" | "br") && matches!(at(i), '"' | '#');
            if raw {
                let hashes = chars[i..].iter().take_while(|&&c| c == '#').count();
                if at(i + hashes) == '"' {
                    let closing: Vec<char> = std::iter::once('"')
                        .chain(std::iter::repeat_n('#', hashes))
                        .collect();
                    i += hashes + 1;
                    while i < chars.len() && !chars[i..].starts_with(&closing) {
                        i += 1;
                    }
                    i += closing.len();
                    continue;
                }
            }
            if word == "b" && at(i) == '"' {
                i = skip_string(&chars, i + 1);
            } else if word == "b" && at(i) == '\'' {
                i += 1;
                while i < chars.len() && chars[i] != '\'' {
                    i += if chars[i] == '\\' { 2 } else { 1 };
                }
                i += 1;
            } else {
                tokens.push(Token::Ident(word));
            }
        } else if c.is_ascii_digit() {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
        } else if c == ':' && at(i + 1) == ':' {
            tokens.push(Token::Colons);
            i += 2;
        } else if c.is_whitespace() {
            i += 1;
        } else {
            tokens.push(Token::Punct(c));
            i += 1;
        }
    }
    tokens
}

/// The index after the string whose body starts at `i`.
fn skip_string(chars: &[char], mut i: usize) -> usize {
    while i < chars.len() && chars[i] != '"' {
        i += if chars[i] == '\\' { 2 } else { 1 };
    }
    i + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(files: &[(&str, &str)]) -> Graph {
        let files = files
            .iter()
            .map(|(p, t)| (p.to_string(), t.to_string()))
            .collect();
        Graph::build(&files)
    }

    fn spelled(graph: &Graph) -> Vec<String> {
        let mut graph = Graph {
            names: graph.names.clone(),
            modules: graph.modules.clone(),
            edges: graph.edges.clone(),
            via: BTreeMap::new(),
        };
        graph.lift();
        graph.circles().iter().map(|c| c.to_string()).collect()
    }

    #[test]
    fn a_circle_is_found_and_spelled_out() {
        let g = tree(&[
            ("lib.rs", "mod a;\nmod b;\nmod c;\n"),
            ("a.rs", "use crate::b::Thing;\n"),
            ("b.rs", "pub fn f() { crate::c::g() }\n"),
            ("c.rs", "use super::a::{self, Other as O};\n"),
        ]);
        assert_eq!(spelled(&g), ["a -> b -> c -> a"]);
    }

    #[test]
    fn a_childs_mod_declaration_and_its_super_paths_are_no_circle() {
        let g = tree(&[
            ("lib.rs", "pub mod app;\n"),
            (
                "app/mod.rs",
                "mod rfu;\npub use rfu::Image;\nuse self::rfu::f;\n",
            ),
            ("app/rfu.rs", "use super::Shared;\nuse crate::app::Other;\n"),
        ]);
        assert!(g.circles().is_empty(), "{:?}", spelled(&g));
        assert_eq!(g.names, ["crate", "app", "app::rfu"]);
        // ...but a parent naming its child by `crate::` is an edge.
        let g = tree(&[
            ("lib.rs", "pub mod app;\n"),
            (
                "app.rs",
                "mod rfu;\nfn f() -> crate::app::rfu::Image { loop {} }\n",
            ),
            ("app/rfu.rs", "use super::Shared;\n"),
        ]);
        assert_eq!(spelled(&g), ["app -> app::rfu -> app"]);
    }

    #[test]
    fn test_code_is_no_edge() {
        let g = tree(&[
            ("lib.rs", "mod a;\nmod b;\n#[cfg(test)]\nmod checks;\n"),
            ("a.rs", "use crate::b::Thing;\n"),
            (
                "b.rs",
                "#[cfg(test)]\nuse crate::a::X;\n\
                 #[cfg(test)]\n#[allow(unused)]\nfn helper() { crate::a::y(); }\n\
                 pub struct Thing;\n\
                 #[cfg(test)]\nmod tests {\n    use crate::a::*;\n    mod deep { fn f() {} }\n}\n\
                 mod inner {\n    #![cfg(test)]\n    use crate::a::Z;\n}\n",
            ),
            ("checks.rs", "use crate::a::A;\nuse crate::b::B;\n"),
        ]);
        assert!(g.circles().is_empty(), "{:?}", spelled(&g));
        assert_eq!(
            g.names,
            ["crate", "a", "b"],
            "a test-only file is no module"
        );
        // The same use outside the test attribute is a circle.
        let g = tree(&[
            ("lib.rs", "mod a;\nmod b;\n"),
            ("a.rs", "use crate::b::Thing;\n"),
            ("b.rs", "#[cfg(not(test))]\nuse crate::a::X;\n"),
        ]);
        assert_eq!(spelled(&g), ["a -> b -> a"]);
    }

    #[test]
    fn a_module_answers_for_its_childrens_paths_out_of_it() {
        let files: BTreeMap<String, String> = [
            ("lib.rs", "mod decode;\nmod decode_app;\n"),
            ("decode.rs", "mod st7580;\npub struct Decoded;\n"),
            (
                "decode/st7580.rs",
                "use super::Decoded;\nuse crate::decode_app::line;\n",
            ),
            ("decode_app.rs", "use crate::decode::Decoded;\n"),
        ]
        .iter()
        .map(|(p, t)| (p.to_string(), t.to_string()))
        .collect();
        let (modules, failures) = check("core", &files);
        assert_eq!(modules, 4);
        assert_eq!(
            failures,
            ["core: decode (by decode::st7580) -> decode_app -> decode"]
        );
    }

    #[test]
    fn comments_strings_and_visibility_are_no_paths() {
        let s = scan(
            "//! see crate::a::b\n/* crate::x /* nested */ crate::y */\n\
             const S: &str = \"crate::z\";\nconst R: &str = r#\"super::q\"#;\n\
             const C: char = '\"'; pub(crate) fn f<'a>(x: &'a u8) {}\n\
             pub(in crate::m) fn g() {}\nfn h() -> crate::real::Thing { loop {} }\n",
        );
        let paths: Vec<Vec<String>> = s.paths.into_iter().map(|(_, p)| p).collect();
        assert_eq!(paths, [["crate", "real", "Thing"]]);
    }

    #[test]
    fn paths_resolve_to_the_longest_module_file() {
        let g = tree(&[
            ("lib.rs", "mod a;\nmod b;\n"),
            (
                "a.rs",
                "mod deep;\npub mod inline { use super::super::b::Thing; }\n",
            ),
            ("a/deep.rs", "use crate::b::{Thing, inner::Item};\n"),
            (
                "b.rs",
                "pub mod inner { pub struct Item; }\nuse crate::a::deep::f;\n",
            ),
        ]);
        let name = |i: usize| g.names[i].as_str();
        let edges: Vec<(&str, &str)> = g
            .edges
            .iter()
            .enumerate()
            .flat_map(|(from, to)| to.iter().map(move |&t| (from, t)))
            .map(|(f, t)| (name(f), name(t)))
            .collect();
        assert_eq!(edges, [("a", "b"), ("b", "a::deep"), ("a::deep", "b")]);
    }

    #[test]
    fn each_root_is_its_own_tree() {
        let g = tree(&[
            ("lib.rs", "pub mod a;\n"),
            ("a.rs", "pub fn f() {}\n"),
            ("main.rs", "mod cli;\nfn main() { cli::run() }\n"),
            ("cli.rs", "use crate::Config;\n"),
        ]);
        assert_eq!(g.names, ["crate", "a", "main.rs", "main.rs: cli"]);
        assert_eq!(g.edges[3], BTreeSet::from([2]));
    }
}
