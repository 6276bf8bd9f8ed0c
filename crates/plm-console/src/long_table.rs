//! Long tables (the Traffic log, the Street's fleet) draw only the rows
//! in view, written as HTML; the table's margins keep the room of the
//! others, so that the scroll bar is the whole table's
//! ([`crate::views::widgets::draw_rows`]).

/// Height of one row of a long table, CSS px (style.css: `#traffic-table
/// td` and `#fleet-table td`, one line of 17 px, 4 px of padding and
/// its 1 px border).
pub const ROW_PX: u32 = 22;
/// Rows drawn past each edge of a long table's view, so that a short
/// scroll shows rows already there.
pub const OVERSCAN: usize = 4;

/// Which of `total` rows a long table draws: those within `view_px`
/// of its scroll position `top_px`, or the last ones when it `follow`s the
/// newest. Only those rows are in the page (issue 13: 500 rows of a busy
/// log took the page 16-24 ms to lay out and paint at every redraw, and
/// the host's ACKs waited behind it).
pub fn window(total: usize, top_px: u32, view_px: u32, follow: bool) -> std::ops::Range<usize> {
    let in_view = view_px.div_ceil(ROW_PX) as usize;
    // The last rows when following, or when the log shrank under the
    // scroll position (cleared, filtered).
    let last_rows = total.saturating_sub(in_view);
    let first = if follow {
        last_rows
    } else {
        ((top_px / ROW_PX) as usize).min(last_rows)
    };
    let first = first.saturating_sub(OVERSCAN);
    first..(first + in_view + 2 * OVERSCAN).min(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_draws_the_rows_in_view_and_follows_the_newest() {
        // 22 px rows, a 220 px view: 10 rows, 4 more past each edge.
        assert_eq!(window(1000, 0, 220, false), 0..18);
        assert_eq!(window(1000, 22 * 100, 220, false), 96..114);
        assert_eq!(window(1000, 22 * 100 + 21, 220, false), 96..114);
        assert_eq!(window(1000, 0, 220, true), 986..1000);
        assert_eq!(window(1000, 22 * 995, 220, false), 986..1000);
        assert_eq!(window(5, 0, 220, true), 0..5);
        assert_eq!(window(0, 440, 220, false), 0..0);
        // Scrolled past what is left after a clear: the last rows.
        assert_eq!(window(3, 22 * 900, 220, false), 0..3);
    }
}
