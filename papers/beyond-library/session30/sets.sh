# Session 30: each set of $T/cases beside the library-residual table of its cases (relative to
# papers/beyond-library), for tables.sh and rule_breaks.sh to source.
SETS="h51:library-residual.md h78:session19/library-residual-780000.md
  h79:session21/library-residual-790000.md h79v:session21/library-residual-790000.md
  h81:session22/library-residual-810000.md h82:session23/library-residual-820000.md
  h82v:session23/library-residual-820000.md h83:session25/library-residual-830000.md
  h83v:session25/library-residual-830000.md h85v:session28/library-residual-850000.md
  h90:session30/library-residual-900000.md h76:session9/library-residual-760000.md
  h77:session9/library-residual-770000.md h68:session6/library-residual-680000.md"
