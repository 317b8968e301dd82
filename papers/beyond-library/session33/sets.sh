# Session 33: session 32's sets and this session's h94, each beside the library-residual table
# of its cases (relative to papers/beyond-library), for tables.sh to source from the root.
. papers/beyond-library/session32/sets.sh
SETS="$SETS h94:session33/library-residual-940000.md"
