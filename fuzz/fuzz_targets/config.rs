//! The `--config` TOML merge of the `polylidar` command (a preset's fields replaced by the
//! file's, tables key by key), then validation and a pipeline built from it: never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polylidar::{Config, Polylidar};

/// As the command's merge: `from`'s keys replace `into`'s, tables merged key by key.
fn merge(into: &mut toml::Table, from: toml::Table) {
    for (key, value) in from {
        match (into.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(table)) => merge(inner, table),
            (_, value) => {
                into.insert(key, value);
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&selector, text)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(text) else {
        return;
    };
    let base = polylidar_fuzz::config_of(selector);
    let Ok(file) = toml::from_str::<toml::Table>(text) else {
        return;
    };
    let mut merged = toml::Table::try_from(&base).expect("a config serializes");
    merge(&mut merged, file);
    if let Ok(config) = merged.try_into::<Config>() {
        let _ = config.validate();
        let _ = Polylidar::new(config);
    }
});
