// A band of a scan's rows, for the stages that compute a scan too large to
// hold whole band by band, each band from the rows around it
// (docs/scale.md, "Big scans").
#pragma once

namespace scanbench::acquisition {

// The arrays at hand hold rows [first_row, first_row + held rows) of a grid
// of `rows` rows; a stage computes grid rows [begin, end), within them.
struct RowBand {
  int rows = 0;       // of the whole grid
  int first_row = 0;  // the grid row of the held arrays' row 0
  int begin = 0;      // grid rows computed: [begin, end)
  int end = 0;

  // The whole grid, held and computed.
  static RowBand whole(int rows) { return {rows, 0, 0, rows}; }
};

}  // namespace scanbench::acquisition
