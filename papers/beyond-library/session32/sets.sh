# Session 32: session 31's sets and this session's h93, each beside the library-residual table
# of its cases (relative to papers/beyond-library), for session 31's tables.sh and
# rule_breaks.sh to source from the root.
. papers/beyond-library/session31/sets.sh
SETS="$SETS h93:session32/library-residual-930000.md"
