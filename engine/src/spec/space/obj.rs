//! A Wavefront OBJ mesh for `objMesh` (3-D spec §4.6): its vertices in file order, its edges
//! in first-seen order and its triangles (for hinges).
//!
//! The subset the spec reads: `v x y z [w]` (w ignored), `f r1 r2 … rk` (k ≥ 3; each
//! reference `i`, `i/t`, `i//n` or `i/t/n`, only `i` used; 1-based, negative counting back
//! from the last vertex defined so far) and `l r1 r2 … rk` (consecutive pairs are edges).
//! Every other statement (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, `mtllib`, comments, `\`
//! continuations of them) is ignored.
//!
//! Why not an OBJ crate: the spec needs every `v` in file order as node k = index − 1 (used or
//! not), coordinates in f64, edges in the file's order of `f` and `l` statements interleaved,
//! and errors with the file's line. The well-kept crates each lose one: `tobj` re-indexes the
//! vertices per object and drops unreferenced ones, `obj-rs` reads positions as f32, keeps
//! faces and lines in separate lists and reports errors without a line. Reading this subset
//! is one pass over the lines.

use std::collections::HashSet;

/// An OBJ file as `objMesh` uses it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// The path as the script writes it.
    pub path: String,
    /// Vertex positions, in file order (node k is the file's vertex k + 1).
    pub vertices: Vec<[f64; 3]>,
    /// Edges (a, b) of the faces (cyclic) and polylines, in file order, each unordered pair
    /// the first time it is seen, endpoints in that order.
    pub edges: Vec<(u32, u32)>,
    /// The triangular faces, for hinges (polygons are not triangulated).
    pub triangles: Vec<[u32; 3]>,
    /// Vertices no face or line refers to (0-based).
    pub unreferenced: Vec<u32>,
    /// Edges whose two ends are the same vertex or coincide.
    pub zero_edges: usize,
}

/// An error in an OBJ file, with the file's line (1-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjError {
    pub line: u32,
    pub message: String,
}

impl std::fmt::Display for ObjError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

impl MeshData {
    /// Reads `text`, the contents of the file the script calls `path`.
    pub fn parse(path: &str, text: &str) -> Result<MeshData, ObjError> {
        let mut mesh = MeshData {
            path: path.to_string(),
            ..MeshData::default()
        };
        let mut seen: HashSet<(u32, u32)> = HashSet::new();
        let mut used: Vec<bool> = Vec::new();
        let mut refs: Vec<u32> = Vec::new();
        for (n, raw) in text.lines().enumerate() {
            let line = u32::try_from(n + 1).unwrap_or(u32::MAX);
            let stmt = raw.split('#').next().unwrap_or("");
            let mut words = stmt.split_ascii_whitespace();
            let Some(keyword) = words.next() else {
                continue;
            };
            let err = |message: String| ObjError { line, message };
            match keyword {
                "v" => {
                    let mut c = [0.0; 3];
                    for (k, slot) in c.iter_mut().enumerate() {
                        let w = words
                            .next()
                            .ok_or_else(|| err(format!("a vertex has 3 coordinates, found {k}")))?;
                        *slot = w
                            .parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| err(format!("`{w}` is not a finite number")))?;
                    }
                    mesh.vertices.push(c);
                    used.push(false);
                }
                "f" | "l" => {
                    refs.clear();
                    for w in words {
                        let index = w.split('/').next().unwrap_or("");
                        let i: i64 = index
                            .parse()
                            .map_err(|_| err(format!("`{w}` is not a vertex reference")))?;
                        let count = mesh.vertices.len() as i64;
                        let k = if i > 0 { i - 1 } else { count + i };
                        if i == 0 || k < 0 || k >= count {
                            return Err(err(format!(
                                "vertex {i} is out of range: {count} vertices are defined so far"
                            )));
                        }
                        refs.push(k as u32);
                    }
                    let least = if keyword == "f" { 3 } else { 2 };
                    if refs.len() < least {
                        return Err(err(format!(
                            "`{keyword}` needs at least {least} vertices, found {}",
                            refs.len()
                        )));
                    }
                    for &r in &refs {
                        used[r as usize] = true;
                    }
                    let pairs = refs.len() - usize::from(keyword == "l");
                    for k in 0..pairs {
                        let (a, b) = (refs[k], refs[(k + 1) % refs.len()]);
                        if seen.insert((a.min(b), a.max(b))) {
                            let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
                            if a == b || p == q {
                                mesh.zero_edges += 1;
                            }
                            mesh.edges.push((a, b));
                        }
                    }
                    if keyword == "f" && refs.len() == 3 {
                        mesh.triangles.push([refs[0], refs[1], refs[2]]);
                    }
                }
                _ => {}
            }
        }
        mesh.unreferenced = used
            .iter()
            .enumerate()
            .filter(|(_, u)| !**u)
            .map(|(k, _)| k as u32)
            .collect();
        Ok(mesh)
    }

    /// The hinges of the triangular faces (3-D spec §4.6 `hinge=`) and how many edges are
    /// shared by more than two faces (which get none).
    pub fn hinges(&self) -> (Vec<(u32, u32)>, usize) {
        super::structures::hinges_of(&self.triangles, &self.edges)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_vertices_faces_and_lines_in_file_order() {
        let text = "# a tetrahedron and a tail\nv 0 0 0\nv 1 0 0\nv 0 1 0 1.0\nvn 0 0 1\nv 0 0 1\n\
                    f 1//1 2//1 3//1\nf 1/1 2/2 4/3\nl 4 -4\no other\nf -1 -2 -3\nv 5 5 5\n";
        let m = MeshData::parse("t.obj", text).unwrap();
        assert_eq!(m.vertices.len(), 5);
        assert_eq!(m.vertices[2], [0.0, 1.0, 0.0]);
        // f 1 2 3: (0,1) (1,2) (2,0); f 1 2 4: (1,3) (3,0); l 4 -4: (3, 0) seen; f -1 -2 -3 at
        // four vertices = 4 3 2: (3,2) new.
        assert_eq!(
            m.edges,
            vec![(0, 1), (1, 2), (2, 0), (1, 3), (3, 0), (3, 2)]
        );
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.unreferenced, vec![4]);
        assert_eq!(m.zero_edges, 0);
    }

    #[test]
    fn errors_name_the_file_line() {
        let e = MeshData::parse("t.obj", "v 0 0 0\nv 1 0\n").unwrap_err();
        assert_eq!((e.line, e.message.contains("3 coordinates")), (2, true));
        let e = MeshData::parse("t.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n").unwrap_err();
        assert_eq!(e.line, 4);
        assert!(e.message.contains("out of range"), "{}", e.message);
        let e = MeshData::parse("t.obj", "v 0 0 x\n").unwrap_err();
        assert_eq!(e.line, 1);
        let e = MeshData::parse("t.obj", "v 0 0 0\nf 1 1\n").unwrap_err();
        assert_eq!(e.line, 2);
        let e = MeshData::parse("t.obj", "v 0 0 inf\n").unwrap_err();
        assert_eq!(e.line, 1);
    }
}
