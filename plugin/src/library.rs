//! The sound library the editor browses: the factory presets beside the user's, each with its
//! display name, category and tags, filtered by a category, a text search and the favourites,
//! and walked with previous/next. No egui here: the browser (`editor/browser.rs`) draws what
//! this decides, and the tests drive it directly.
//!
//! Favourites are kept per user in `favourites.txt` in the user preset folder
//! ([`crate::files::user_preset_dir`]), one key per line: `factory:ID` or `user:NAME`.

use crate::files::{read_script, save_script, UserPreset};
use crate::presets::{category, tags, CATEGORIES, FIELDS, LIBRARY_FIELDS, PRESETS};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The favourites file in the user preset folder.
pub const FAVOURITES_FILE: &str = "favourites.txt";

/// Where an entry's script comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A built-in preset, by its index in [`PRESETS`].
    Factory(usize),
    User(PathBuf),
}

/// One preset of the library.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Stable across sessions: `factory:felt-piano`, `user:My Bell`.
    pub key: String,
    /// The model name a load gives it: a factory preset's id, a user preset's file stem.
    pub id: String,
    /// What the browser shows: the header's title line (`# Felt Piano`), else the id.
    pub name: String,
    pub category: Option<&'static str>,
    pub tags: Vec<String>,
    pub source: Source,
}

impl Entry {
    pub fn is_user(&self) -> bool {
        matches!(self.source, Source::User(_))
    }

    /// The script, read from the user's file when it is one.
    pub fn script(&self) -> Result<String, String> {
        match &self.source {
            Source::Factory(i) => Ok(PRESETS[*i].text.to_string()),
            Source::User(path) => read_script(path),
        }
    }
}

/// The title of a script: its first line when that is a `# ` comment that starts no header
/// field.
pub fn title(text: &str) -> Option<String> {
    let first = text.lines().next()?.strip_prefix('#')?.trim();
    let is_field = FIELDS
        .iter()
        .chain(&LIBRARY_FIELDS)
        .chain(&["Plugin:"])
        .any(|f| first.starts_with(f));
    (!first.is_empty() && !is_field).then(|| first.to_string())
}

/// Every factory preset, by category in the order of [`CATEGORIES`] (in [`PRESETS`] order
/// within one), then the user presets by name (with the category and tags their headers give,
/// if any).
pub fn entries(user: &[UserPreset]) -> Vec<Entry> {
    let mut out: Vec<Entry> = PRESETS
        .iter()
        .enumerate()
        .map(|(i, p)| Entry {
            key: format!("factory:{}", p.id),
            id: p.id.to_string(),
            name: title(p.text).unwrap_or_else(|| p.id.to_string()),
            category: category(p.text),
            tags: tags(p.text),
            source: Source::Factory(i),
        })
        .collect();
    let rank = |c: Option<&str>| {
        c.and_then(|c| CATEGORIES.iter().position(|&k| k == c))
            .unwrap_or(CATEGORIES.len())
    };
    out.sort_by_key(|e| rank(e.category));
    for u in user {
        // A user preset that cannot be read is still listed: loading it reports why.
        let text = read_script(&u.path).unwrap_or_default();
        out.push(Entry {
            key: format!("user:{}", u.name),
            id: u.name.clone(),
            name: u.name.clone(),
            category: category(&text),
            tags: tags(&text),
            source: Source::User(u.path.clone()),
        });
    }
    out
}

/// What the browser shows of the library.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Filter {
    /// One of [`crate::presets::CATEGORIES`], or every category.
    pub category: Option<&'static str>,
    /// Words that must each appear in the name, id, category or a tag (any case).
    pub query: String,
    pub favourites_only: bool,
    /// Factory presets, user presets, or both.
    pub show_factory: bool,
    pub show_user: bool,
}

impl Filter {
    /// Everything.
    pub fn all() -> Filter {
        Filter {
            show_factory: true,
            show_user: true,
            ..Filter::default()
        }
    }

    pub fn matches(&self, e: &Entry, favourites: &Favourites) -> bool {
        if !(if e.is_user() {
            self.show_user
        } else {
            self.show_factory
        }) {
            return false;
        }
        if self.category.is_some() && e.category != self.category {
            return false;
        }
        if self.favourites_only && !favourites.contains(&e.key) {
            return false;
        }
        let hay = format!(
            "{} {} {} {}",
            e.name,
            e.id,
            e.category.unwrap_or(""),
            e.tags.join(" ")
        )
        .to_lowercase();
        self.query
            .split_whitespace()
            .all(|w| hay.contains(&w.to_lowercase()))
    }

    /// The indices of the entries it shows, in library order.
    pub fn apply(&self, entries: &[Entry], favourites: &Favourites) -> Vec<usize> {
        (0..entries.len())
            .filter(|&i| self.matches(&entries[i], favourites))
            .collect()
    }
}

/// The entry `step` places from `current` in the shown list `shown` (wrapping round), or the
/// first (the last, going back) when `current` is not shown. None for an empty list.
pub fn neighbour(shown: &[usize], current: Option<usize>, step: isize) -> Option<usize> {
    if shown.is_empty() {
        return None;
    }
    let n = shown.len() as isize;
    let at = current.and_then(|c| shown.iter().position(|&i| i == c));
    let next = match at {
        Some(k) => (k as isize + step).rem_euclid(n),
        None if step < 0 => n - 1,
        None => 0,
    };
    Some(shown[next as usize])
}

/// The user's favourite presets, by entry key, and the file they are kept in.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Favourites {
    keys: BTreeSet<String>,
    file: Option<PathBuf>,
}

impl Favourites {
    /// The favourites saved in `dir` (none when the file is missing or unreadable).
    pub fn load(dir: Option<&Path>) -> Favourites {
        let file = dir.map(|d| d.join(FAVOURITES_FILE));
        let keys = file
            .as_deref()
            .and_then(|f| std::fs::read_to_string(f).ok())
            .map(|text| {
                text.lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty() && !l.starts_with('#'))
                    .map(String::from)
                    .collect()
            })
            .unwrap_or_default();
        Favourites { keys, file }
    }

    pub fn contains(&self, key: &str) -> bool {
        self.keys.contains(key)
    }

    pub fn len(&self) -> usize {
        self.keys.len()
    }

    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// Adds or removes `key` and saves the file. The change holds for this session even when
    /// the file cannot be written; the error says why.
    pub fn toggle(&mut self, key: &str) -> Result<(), String> {
        if !self.keys.remove(key) {
            self.keys.insert(key.to_string());
        }
        let Some(file) = &self.file else {
            return Err("no user data folder: favourites last for this session".into());
        };
        let mut text = String::from("# Ressort favourites, one preset per line\n");
        for k in &self.keys {
            text.push_str(k);
            text.push('\n');
        }
        save_script(file, &text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("ressort-library-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Issue 37's per-preset check: the browser finds every factory preset by its category and
    /// by each of its tags, and shows its title.
    #[test]
    fn the_browser_finds_every_preset_by_its_category_and_by_each_tag() {
        let lib = entries(&[]);
        let none = Favourites::default();
        assert_eq!(lib.len(), PRESETS.len());
        for (i, e) in lib.iter().enumerate() {
            assert!(
                !e.name.contains(':') && e.name != e.id,
                "{}: title {:?}",
                e.id,
                e.name
            );
            let by_category = Filter {
                category: e.category,
                ..Filter::all()
            };
            assert!(e.category.is_some(), "{}", e.id);
            assert!(by_category.apply(&lib, &none).contains(&i), "{}", e.id);
            for tag in &e.tags {
                let by_tag = Filter {
                    query: tag.to_uppercase(),
                    ..Filter::all()
                };
                assert!(by_tag.apply(&lib, &none).contains(&i), "{} by {tag}", e.id);
            }
            let by_name = Filter {
                query: e.name.clone(),
                ..Filter::all()
            };
            assert!(by_name.apply(&lib, &none).contains(&i), "{}", e.id);
        }
        // Every category of the library holds presets, listed together in the browser's order.
        let ranks: Vec<usize> = lib
            .iter()
            .map(|e| {
                CATEGORIES
                    .iter()
                    .position(|&c| Some(c) == e.category)
                    .unwrap()
            })
            .collect();
        assert!(ranks.windows(2).all(|w| w[0] <= w[1]), "{ranks:?}");
        for c in CATEGORIES {
            let f = Filter {
                category: Some(c),
                ..Filter::all()
            };
            assert!(!f.apply(&lib, &none).is_empty(), "{c} is empty");
        }
    }

    #[test]
    fn a_search_needs_every_word_and_a_category_narrows_it() {
        let lib = entries(&[]);
        let none = Favourites::default();
        let find = |f: Filter| -> Vec<String> {
            f.apply(&lib, &none)
                .iter()
                .map(|&i| lib[i].id.clone())
                .collect()
        };
        let bowed = find(Filter {
            query: "bow".into(),
            ..Filter::all()
        });
        assert!(bowed.contains(&"bowed-string".to_string()), "{bowed:?}");
        let narrowed = find(Filter {
            query: "bow string".into(),
            category: Some("Strings / Bowed"),
            ..Filter::all()
        });
        assert!(!narrowed.is_empty() && narrowed.len() <= bowed.len());
        assert!(narrowed.iter().all(|id| lib
            .iter()
            .any(|e| &e.id == id && e.category == Some("Strings / Bowed"))));
        assert!(find(Filter {
            query: "no such word anywhere".into(),
            ..Filter::all()
        })
        .is_empty());
        assert!(find(Filter {
            show_factory: false,
            ..Filter::all()
        })
        .is_empty());
    }

    #[test]
    fn next_and_previous_walk_the_shown_list_and_wrap_round() {
        let shown = [2, 5, 9];
        assert_eq!(neighbour(&shown, Some(5), 1), Some(9));
        assert_eq!(neighbour(&shown, Some(9), 1), Some(2));
        assert_eq!(neighbour(&shown, Some(2), -1), Some(9));
        assert_eq!(neighbour(&shown, Some(7), 1), Some(2));
        assert_eq!(neighbour(&shown, None, -1), Some(9));
        assert_eq!(neighbour(&[], Some(1), 1), None);
    }

    #[test]
    fn favourites_are_saved_per_user_and_filter_the_list() {
        let dir = temp_dir("favourites");
        let mut fav = Favourites::load(Some(&dir));
        assert!(fav.is_empty());
        fav.toggle("factory:felt-piano").unwrap();
        fav.toggle("factory:marimba").unwrap();
        fav.toggle("factory:marimba").unwrap();
        let again = Favourites::load(Some(&dir));
        assert!(again.contains("factory:felt-piano") && !again.contains("factory:marimba"));
        assert_eq!(again.len(), 1);
        let lib = entries(&[]);
        let only = Filter {
            favourites_only: true,
            ..Filter::all()
        };
        let shown = only.apply(&lib, &again);
        assert_eq!(shown.len(), 1);
        assert_eq!(lib[shown[0]].id, "felt-piano");
        // Without a folder the change holds for the session and says why it is not saved.
        let mut session = Favourites::load(None);
        assert!(session.toggle("user:x").is_err());
        assert!(session.contains("user:x"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn user_presets_sit_beside_the_factory_ones_with_their_own_header() {
        let dir = temp_dir("user");
        std::fs::write(
            dir.join("My Bell.mdl"),
            "# My Bell\n# Category: Bells and Plates\n# Tags: mine, bell\n@m mass 1 0 0\n",
        )
        .unwrap();
        std::fs::write(dir.join("plain.mdl"), "@m mass 1 0 0\n").unwrap();
        let user = crate::files::user_presets(&dir);
        let lib = entries(&user);
        assert_eq!(lib.len(), PRESETS.len() + 2);
        let bell = lib.iter().position(|e| e.id == "My Bell").unwrap();
        assert!(lib[bell].is_user());
        assert_eq!(lib[bell].key, "user:My Bell");
        assert_eq!(lib[bell].category, Some("Bells and Plates"));
        let mine = Filter {
            query: "mine".into(),
            ..Filter::all()
        };
        assert_eq!(mine.apply(&lib, &Favourites::default()), vec![bell]);
        let users = Filter {
            show_factory: false,
            ..Filter::all()
        };
        assert_eq!(users.apply(&lib, &Favourites::default()).len(), 2);
        assert!(lib[bell].script().unwrap().contains("@m mass"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_title_is_the_first_comment_line_unless_it_is_a_field() {
        assert_eq!(
            title("# Felt Piano\n#\n# What: x\n").as_deref(),
            Some("Felt Piano")
        );
        assert_eq!(title("# What: a model\n"), None);
        assert_eq!(title("@m mass 1 0 0\n"), None);
        assert_eq!(title("#\n# Felt\n"), None);
    }
}
