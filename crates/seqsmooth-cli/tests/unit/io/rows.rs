//! Unit tests of `io::rows`: chunks of rows, their lines, cells and series.

use seqsmooth_cli::io::rows::*;
use seqsmooth_cli::io::Need;

fn read_all(text: &str, id: Option<&str>, max: usize) -> (Vec<Chunk>, Vec<Vec<u8>>) {
    let mut r = RowReader::new(text.as_bytes(), "t", "y", id, &Need::degree(0)).unwrap();
    let (mut chunks, mut ids) = (Vec::new(), Vec::new());
    loop {
        let mut c = Chunk::default();
        r.read_chunk(&mut c, max);
        ids.extend(c.new_ids.iter().cloned());
        let stop = c.done || c.error.is_some();
        chunks.push(c);
        if stop {
            return (chunks, ids);
        }
    }
}

#[test]
#[allow(clippy::len_zero)] // the assertion as it stood in src, kept word for word
fn chunks_lines_cells_and_series() {
    let text = "id,t,y\na,0,1\n\"b,1\", 0.5 ,2\n\na,1,3e0\nc\"x,1,4\n";
    let (chunks, ids) = read_all(text, Some("id"), 2);
    // Two full chunks, then the end of the input in an empty one.
    assert_eq!(chunks.len(), 3);
    assert!(chunks[2].done && chunks[2].error.is_none() && chunks[2].len() == 0);
    assert_eq!(chunks[1].rows_read, 4);
    let rows: Vec<(u64, usize, String)> = chunks
        .iter()
        .flat_map(|c| {
            (0..c.len()).map(move |i| {
                let mut echo = Vec::new();
                c.echo(&mut echo, i, None);
                (c.lines[i], c.series[i], String::from_utf8(echo).unwrap())
            })
        })
        .collect();
    assert_eq!(
        rows,
        [
            (2, 0, "0,1".into()),
            (3, 1, "0.5,2".into()),
            (5, 0, "1,3e0".into()),
            (6, 2, "1,4".into()),
        ]
    );
    assert_eq!(
        ids,
        [b"a".to_vec(), b"\"b,1\"".to_vec(), b"\"c\"\"x\"".to_vec()]
    );
}

#[test]
fn time_order_is_per_series() {
    let text = "id,t,y\na,5,1\nb,1,1\na,6,1\nb,2,1\nb,2,1\n";
    let (chunks, _) = read_all(text, Some("id"), 100);
    assert_eq!(chunks[0].len(), 4);
    let e = chunks[0].error.as_ref().unwrap().to_string();
    assert_eq!(
        e,
        "line 6: time 2 is not after the previous time 2 (line 5) of series 'b': duplicate \
         time; times must be strictly increasing"
    );
    // Across chunks: the previous time's text is kept.
    let (chunks, _) = read_all("t,y\n0,1\n1.50,1\n1.5,2\n", None, 2);
    let e = chunks[1].error.as_ref().unwrap().to_string();
    assert!(e.starts_with("line 4: time 1.5 is not after the previous time 1.50 (line 3)"));
}

#[test]
fn bad_cells_stop_the_chunk_with_line_and_column() {
    let (chunks, _) = read_all("t,y\n0,1\n1,NaN\n2,3\n", None, 100);
    assert_eq!(chunks[0].len(), 1);
    assert_eq!(
        chunks[0].error.as_ref().unwrap().to_string(),
        "line 3, column 'y': value NaN is not finite"
    );
}
