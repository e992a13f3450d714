//! The mesh files shipped with Ressort (`models/*.obj`), which the presets' `objMesh` lines
//! import (3-D spec §4.6). A script the instrument plays is text alone (a host keeps the text
//! in its project), so the meshes a preset needs travel inside the program, as the presets do.

/// The shipped meshes, by the file name a script writes.
const SHIPPED: [(&str, &str); 2] = [
    ("bell.obj", include_str!("../../../models/bell.obj")),
    (
        "bell-coarse.obj",
        include_str!("../../../models/bell-coarse.obj"),
    ),
];

/// The file `path` of the shipped meshes (a path ending in a shipped file's name, such as
/// `models/bell.obj`, finds it too).
pub fn shipped(path: &str) -> Result<String, String> {
    let name = path.rsplit(['/', '\\']).next().unwrap_or(path);
    SHIPPED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| text.to_string())
        .ok_or_else(|| {
            let names: Vec<&str> = SHIPPED.iter().map(|(n, _)| *n).collect();
            format!(
                "no mesh `{path}` among those shipped with Ressort ({}); a script played by the \
                 plugin imports those only",
                names.join(", ")
            )
        })
}
