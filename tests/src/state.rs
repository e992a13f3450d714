//! Helpers for nice-plug's state format: an 8-byte little-endian length, then JSON
//! `{"version", "params": {string id: plain value}, "fields": {name: JSON text}}`. Ressort keeps
//! its model in the field `"model"`: `{"name": …, "script": …}`.

use serde_json::Value;

/// The JSON part of a state blob.
pub fn json(blob: &[u8]) -> Option<Value> {
    let len = u64::from_le_bytes(blob.get(..8)?.try_into().ok()?) as usize;
    serde_json::from_slice(blob.get(8..8 + len)?).ok()
}

/// The state's JSON with the model's kept analyses left out: in a realtime host a state saved
/// before a new script's exact analyses finished has none, and one saved after has them; both
/// are the same project.
pub fn json_without_analyses(blob: &[u8]) -> Option<Value> {
    let mut v = json(blob)?;
    let field = v.get("fields")?.get("model")?.as_str()?;
    let mut m: Value = serde_json::from_str(field).ok()?;
    m.as_object_mut()?.remove("analyses");
    *v.get_mut("fields")?.get_mut("model")? = Value::String(m.to_string());
    Some(v)
}

/// Whether the state's model carries analyses (the process kept them for its script).
pub fn has_analyses(blob: &[u8]) -> bool {
    json(blob)
        .and_then(|v| {
            let field = v.get("fields")?.get("model")?.as_str()?.to_string();
            serde_json::from_str::<Value>(&field).ok()
        })
        .is_some_and(|m| m.get("analyses").is_some())
}

/// A state blob around JSON bytes (the length prefix added).
pub fn blob(json: &[u8]) -> Vec<u8> {
    let mut out = (json.len() as u64).to_le_bytes().to_vec();
    out.extend_from_slice(json);
    out
}

/// A state blob from a JSON value.
pub fn blob_from(value: &Value) -> Vec<u8> {
    blob(&serde_json::to_vec(value).expect("JSON"))
}

/// The model (name, script) saved in a state blob.
pub fn model(blob: &[u8]) -> Option<(String, String)> {
    let v = json(blob)?;
    let field = v.get("fields")?.get("model")?.as_str()?;
    let m: Value = serde_json::from_str(field).ok()?;
    Some((
        m.get("name")?.as_str()?.to_string(),
        m.get("script")?.as_str()?.to_string(),
    ))
}

/// A plain parameter value saved in a state blob, by the parameter's string id.
pub fn param(blob: &[u8], id: &str) -> Option<Value> {
    json(blob)?.get("params")?.get(id).cloned()
}

/// A copy of a state blob with another model.
pub fn with_model(blob: &[u8], name: &str, script: &str) -> Vec<u8> {
    let mut v = json(blob).expect("a valid state blob");
    let model = serde_json::json!({ "name": name, "script": script }).to_string();
    v["fields"]["model"] = Value::String(model);
    blob_from(&v)
}

/// A copy of a state blob with another model, played by today's conventions (concert
/// pitch, automatic levels): a state [`with_model`] writes has no `playing` field, as
/// projects saved before them, and plays as they did.
pub fn with_musical_model(blob: &[u8], name: &str, script: &str) -> Vec<u8> {
    let mut v = json(blob).expect("a valid state blob");
    let model =
        serde_json::json!({ "name": name, "script": script, "playing": "musical" }).to_string();
    v["fields"]["model"] = Value::String(model);
    blob_from(&v)
}

/// The `playing` field of the model saved in a state blob (None: a legacy project's).
pub fn playing(blob: &[u8]) -> Option<String> {
    let v = json(blob)?;
    let field = v.get("fields")?.get("model")?.as_str()?;
    let m: Value = serde_json::from_str(field).ok()?;
    Some(m.get("playing")?.as_str()?.to_string())
}

/// A copy of a state blob with a persistent field set to `json` (its JSON text).
pub fn with_field(blob: &[u8], name: &str, json: &str) -> Vec<u8> {
    let mut v = self::json(blob).expect("a valid state blob");
    v["fields"][name] = Value::String(json.to_string());
    blob_from(&v)
}

/// A copy of a state blob with a parameter set (plain value, by string id).
pub fn with_param(blob: &[u8], id: &str, value: Value) -> Vec<u8> {
    let mut v = json(blob).expect("a valid state blob");
    v["params"][id] = value;
    blob_from(&v)
}
