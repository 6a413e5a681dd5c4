//! Length units of coordinates, and the unit a LAS/LAZ header declares.
//!
//! The rules for LAS/LAZ headers are on [`LengthUnit`].

use std::fmt;
use std::str::FromStr;

/// A unit of length for point coordinates.
///
/// A LAS file says its horizontal unit in its coordinate reference system records, if it
/// has any (the LAS 1.4 specification, §2.5): an OGC WKT record (`LASF_Projection`, record
/// 2112) or GeoTIFF keys (`LASF_Projection`, record 34735). [`read_las`](crate::read_las) reads them
/// in this order (the result is [`LasCloud::unit`](crate::LasCloud::unit)):
///
/// 1. the WKT's linear unit: the `UNIT[name, metres per unit]` (WKT 1) or `LENGTHUNIT`
///    (WKT 2) that belongs to the projected system itself, not to its geographic base;
/// 2. the GeoTIFF key `ProjLinearUnitsGeoKey` (3076): EPSG 9001 metre, 9002 foot, 9003 US
///    survey foot; else `VerticalUnitsGeoKey` (4099) with the same codes;
/// 3. nothing: the unit is unknown (`None`), and callers assume metres unless told.
///
/// `autzen_trim.laz` of `../shared/fixtures` declares "foot" (0.3048 m, EPSG 9002) in both
/// its WKT and its GeoTIFF keys; `simple.las` has no records at all (unknown).
///
/// ```
/// use polylidar_io::LengthUnit;
/// let unit: LengthUnit = "us-ft".parse().unwrap();
/// assert_eq!(unit, LengthUnit::UsSurveyFoot);
/// assert!((unit.metres() - 1200.0 / 3937.0).abs() < 1e-15);
/// assert_eq!(LengthUnit::from_metres(0.3048), Some(LengthUnit::Foot));
/// assert_eq!(LengthUnit::Foot.to_string(), "ft");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LengthUnit {
    /// The metre (EPSG 9001).
    Metre,
    /// The international foot, 0.3048 m (EPSG 9002).
    Foot,
    /// The US survey foot, 1200/3937 m (EPSG 9003).
    UsSurveyFoot,
}

impl LengthUnit {
    /// Every unit.
    pub const ALL: [LengthUnit; 3] = [Self::Metre, Self::Foot, Self::UsSurveyFoot];

    /// Metres in one unit.
    pub fn metres(self) -> f64 {
        match self {
            Self::Metre => 1.0,
            Self::Foot => 0.3048,
            Self::UsSurveyFoot => 1200.0 / 3937.0,
        }
    }

    /// The short name: `m`, `ft`, `us-ft` (also what [`FromStr`] accepts).
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Metre => "m",
            Self::Foot => "ft",
            Self::UsSurveyFoot => "us-ft",
        }
    }

    /// The unit of this many metres (relative tolerance 10⁻⁹), if it is one of these.
    pub fn from_metres(metres: f64) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|u| (u.metres() - metres).abs() <= 1e-9 * metres.abs())
    }

    /// The unit of an EPSG linear unit code (9001, 9002, 9003).
    pub fn from_epsg(code: u16) -> Option<Self> {
        match code {
            9001 => Some(Self::Metre),
            9002 => Some(Self::Foot),
            9003 => Some(Self::UsSurveyFoot),
            _ => None,
        }
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// A name that is not a known unit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown length unit `{0}`; use m, ft or us-ft")]
pub struct UnknownUnit(pub String);

impl FromStr for LengthUnit {
    type Err = UnknownUnit;

    /// `m` / `metre` / `meter` / `metres`, `ft` / `foot` / `feet`, `us-ft` / `us-foot` /
    /// `us-survey-foot`, any case.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "m" | "metre" | "meter" | "metres" | "meters" => Ok(Self::Metre),
            "ft" | "foot" | "feet" => Ok(Self::Foot),
            "us-ft" | "us-foot" | "us-feet" | "us-survey-foot" | "ftus" => Ok(Self::UsSurveyFoot),
            _ => Err(UnknownUnit(s.to_owned())),
        }
    }
}

/// The horizontal length unit a LAS/LAZ header declares, by the rules of the module docs;
/// `None` when it declares none this reader knows.
pub(crate) fn las_header_unit(header: &las::Header) -> Option<LengthUnit> {
    let projection = |id| {
        header
            .all_vlrs()
            .find(|v| v.user_id == "LASF_Projection" && v.record_id == id)
    };
    let from_wkt =
        projection(2112).and_then(|v| wkt_linear_unit(&String::from_utf8_lossy(&v.data)));
    from_wkt.or_else(|| projection(34735).and_then(|v| geotiff_linear_unit(&v.data)))
}

/// The linear unit of a WKT projected system: the `UNIT` / `LENGTHUNIT` directly inside
/// `PROJCS[...]` / `PROJCRS[...]`, by its conversion factor (its name where the factor is
/// missing).
pub fn wkt_linear_unit(wkt: &str) -> Option<LengthUnit> {
    let start = ["PROJCS[", "PROJCRS["]
        .iter()
        .filter_map(|key| wkt.find(key).map(|at| at + key.len()))
        .min()?;
    let body = &wkt[start..];
    let mut depth = 0usize;
    let mut in_quotes = false;
    let mut unit = None;
    for (i, c) in body.char_indices() {
        match c {
            '"' => in_quotes = !in_quotes,
            '[' | '(' if !in_quotes => {
                if depth == 0 {
                    let keyword = body[..i]
                        .rsplit(|c: char| !c.is_ascii_alphanumeric() && c != '_')
                        .next()
                        .unwrap_or("");
                    if keyword.eq_ignore_ascii_case("UNIT")
                        || keyword.eq_ignore_ascii_case("LENGTHUNIT")
                    {
                        unit = unit_node(&body[i + 1..]).or(unit);
                    }
                }
                depth += 1;
            }
            ']' | ')' if !in_quotes => {
                if depth == 0 {
                    break;
                }
                depth -= 1;
            }
            _ => {}
        }
    }
    unit
}

/// The unit of a WKT `UNIT` node's arguments (`"foot",0.3048,...]`).
fn unit_node(args: &str) -> Option<LengthUnit> {
    let mut fields = args.split([',', ']']);
    let name = fields.next()?.trim().trim_matches('"');
    let factor = fields.next().and_then(|f| f.trim().parse::<f64>().ok());
    match factor {
        Some(metres) => LengthUnit::from_metres(metres),
        None => name.parse().ok(),
    }
}

/// The linear unit of a GeoTIFF GeoKeyDirectory (`u16` little-endian: a 4-entry header,
/// then keys of 4 entries: id, location, count, value).
pub fn geotiff_linear_unit(directory: &[u8]) -> Option<LengthUnit> {
    let words: Vec<u16> = directory
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect();
    let keys = usize::from(*words.get(3)?);
    let value = |id: u16| {
        words
            .get(4..)?
            .chunks_exact(4)
            .take(keys)
            .find(|k| k[0] == id && k[1] == 0)
            .map(|k| k[3])
    };
    [3076, 4099]
        .into_iter()
        .find_map(|id| value(id).and_then(LengthUnit::from_epsg))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wkt_unit_is_the_projected_systems_not_the_geographic_bases() {
        let feet = r#"PROJCS["x",GEOGCS["g",DATUM["d",SPHEROID["s",6378137,298.26]],UNIT["degree",0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],UNIT["foot",0.3048,AUTHORITY["EPSG","9002"]]]"#;
        assert_eq!(wkt_linear_unit(feet), Some(LengthUnit::Foot));
        let us = r#"COMPD_CS["c",PROJCS["p",GEOGCS["g",UNIT["degree",0.01745]],UNIT["US survey foot",0.304800609601219]],VERT_CS["v",UNIT["metre",1]]]"#;
        assert_eq!(wkt_linear_unit(us), Some(LengthUnit::UsSurveyFoot));
        let wkt2 = r#"PROJCRS["p",BASEGEOGCRS["g",ANGLEUNIT["degree",0.01745]],CS[Cartesian,2],LENGTHUNIT["metre",1]]"#;
        assert_eq!(wkt_linear_unit(wkt2), Some(LengthUnit::Metre));
        assert_eq!(
            wkt_linear_unit(r#"GEOGCS["g",UNIT["degree",0.01745]]"#),
            None
        );
        assert_eq!(
            wkt_linear_unit(r#"PROJCS["p",UNIT["link",0.201168]]"#),
            None
        );
    }

    #[test]
    fn geotiff_keys_give_the_epsg_unit() {
        let directory = |keys: &[[u16; 4]]| -> Vec<u8> {
            let mut words = vec![1u16, 1, 0, keys.len() as u16];
            words.extend(keys.iter().flatten());
            words.iter().flat_map(|w| w.to_le_bytes()).collect()
        };
        let model = [1024, 0, 1, 1];
        assert_eq!(
            geotiff_linear_unit(&directory(&[model, [3076, 0, 1, 9003]])),
            Some(LengthUnit::UsSurveyFoot)
        );
        assert_eq!(
            geotiff_linear_unit(&directory(&[model, [4099, 0, 1, 9001]])),
            Some(LengthUnit::Metre)
        );
        assert_eq!(geotiff_linear_unit(&directory(&[model])), None);
        assert_eq!(geotiff_linear_unit(&[1, 0]), None);
    }

    #[test]
    fn names_parse_back() {
        for unit in LengthUnit::ALL {
            assert_eq!(unit.symbol().parse::<LengthUnit>(), Ok(unit));
            assert_eq!(LengthUnit::from_metres(unit.metres()), Some(unit));
        }
        assert!("yard".parse::<LengthUnit>().is_err());
    }

    #[test]
    fn fixture_headers_declare_their_units() {
        let Some(autzen) = test_fixtures::fixture("lidar/autzen_trim.laz") else {
            return;
        };
        assert_eq!(
            crate::read_las(autzen).unwrap().unit,
            Some(LengthUnit::Foot)
        );
        let Some(simple) = test_fixtures::fixture("lidar/simple.las") else {
            return;
        };
        assert_eq!(crate::read_las_unit(&simple).unwrap(), None);
        assert_eq!(crate::read_las(simple).unwrap().unit, None);
    }
}
