# Session 31: session 30's sets and this session's h91 and h92, each beside the
# library-residual table of its cases (relative to papers/beyond-library), for tables.sh and
# rule_breaks.sh to source from the root.
. papers/beyond-library/session30/sets.sh
SETS="$SETS h91:session31/library-residual-910000.md h92:session31/library-residual-920000.md"
