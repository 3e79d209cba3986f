//! The columns of `seqsmooth filter`'s output and the text of its rows.
//!
//! Rows are written straight into a byte buffer: the echoed cells as read, numbers with
//! round-trip precision ([`write_f64`]), no allocation per row.

use crate::filter::{Cells, Extra};
use crate::number::write_f64;
use crate::rows::csv_field;

/// The output columns: `[id,]t,y,d0..dM[,s0..sM][,extra…]`.
#[derive(Clone, Debug)]
pub struct Layout {
    /// The id column's name, with `--id-col`.
    pub id: Option<String>,
    /// Degree `M`.
    pub degree: usize,
    /// Whether the `s0..sM` columns are written.
    pub sigma: bool,
    /// The trailing columns.
    pub extra: &'static [&'static str],
}

impl Layout {
    /// The number of value slots per row: `d0..dM`, and `s0..sM` with [`Layout::sigma`].
    pub fn stride(&self) -> usize {
        (self.degree + 1) * if self.sigma { 2 } else { 1 }
    }

    /// The header line.
    pub fn header(&self) -> Vec<u8> {
        let mut cells: Vec<Vec<u8>> = Vec::new();
        if let Some(id) = &self.id {
            cells.push(csv_field(id.as_bytes()));
        }
        cells.push(b"t".to_vec());
        cells.push(b"y".to_vec());
        cells.extend((0..=self.degree).map(|k| format!("d{k}").into_bytes()));
        if self.sigma {
            cells.extend((0..=self.degree).map(|k| format!("s{k}").into_bytes()));
        }
        cells.extend(self.extra.iter().map(|c| c.as_bytes().to_vec()));
        let mut line = cells.join(&b","[..]);
        line.push(b'\n');
        line
    }

    /// Appends one row: the id cell (with `--id-col`), the echoed time and value cells, the
    /// values (`values[..m+1]` the derivatives, `values[m+1..]` their 1σ; empty cells past
    /// the counts in `cells`), and the trailing cells.
    pub fn row(
        &self,
        out: &mut Vec<u8>,
        id: Option<&[u8]>,
        t: &[u8],
        y: &[u8],
        values: &[f64],
        cells: &Cells,
    ) {
        if let Some(id) = id {
            out.extend_from_slice(id);
            out.push(b',');
        }
        out.extend_from_slice(t);
        out.push(b',');
        out.extend_from_slice(y);
        let width = self.degree + 1;
        for (k, &v) in values[..width].iter().enumerate() {
            out.push(b',');
            if k < cells.derivatives {
                write_f64(out, v);
            }
        }
        if self.sigma {
            for (k, &v) in values[width..2 * width].iter().enumerate() {
                out.push(b',');
                if k < cells.std_devs {
                    write_f64(out, v);
                }
            }
        }
        match cells.extra {
            Extra::None => {}
            Extra::Window(w) => {
                out.push(b',');
                // Writing to a Vec cannot fail.
                let _ = std::io::Write::write_fmt(out, format_args!("{w}"));
            }
            Extra::Auto {
                noise,
                outlier,
                misfit,
            } => {
                out.push(b',');
                if let Some(s) = noise {
                    write_f64(out, s);
                }
                out.extend_from_slice(if outlier { b",1" } else { b",0" });
                out.extend_from_slice(if misfit { b",1" } else { b",0" });
            }
        }
        out.push(b'\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_rows() {
        let layout = Layout {
            id: Some("sensor id".into()),
            degree: 1,
            sigma: true,
            extra: &["noise", "outlier", "misfit"],
        };
        assert_eq!(layout.stride(), 4);
        assert_eq!(
            String::from_utf8(layout.header()).unwrap(),
            "sensor id,t,y,d0,d1,s0,s1,noise,outlier,misfit\n"
        );
        let mut out = Vec::new();
        let cells = Cells {
            derivatives: 1,
            std_devs: 1,
            extra: Extra::Auto {
                noise: Some(0.5),
                outlier: true,
                misfit: false,
            },
        };
        layout.row(
            &mut out,
            Some(b"\"a,b\""),
            b"1.0",
            b"2",
            &[0.1, 9.0, 1e-300, 9.0],
            &cells,
        );
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "\"a,b\",1.0,2,0.1,,1e-300,,0.5,1,0\n"
        );
        let layout = Layout {
            id: None,
            degree: 0,
            sigma: false,
            extra: &["window"],
        };
        assert_eq!(
            String::from_utf8(layout.header()).unwrap(),
            "t,y,d0,window\n"
        );
        let mut out = Vec::new();
        let cells = Cells {
            derivatives: 0,
            std_devs: 0,
            extra: Extra::Window(3),
        };
        layout.row(&mut out, None, b"1", b"2", &[f64::NAN], &cells);
        assert_eq!(String::from_utf8(out).unwrap(), "1,2,,3\n");
    }
}
