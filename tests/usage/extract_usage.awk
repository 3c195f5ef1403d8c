# Turns the USAGE example of a public header into a program: the lines
# after " * USAGE" up to the end of the comment (or a bare " *") become the
# body of main(), which returns 0 when the example runs to its end. Run as
#   awk -v header=luxel/core.h -f extract_usage.awk include/luxel/core.h
BEGIN {
    print "/* Generated from the USAGE example of " header " by extract_usage.awk. */"
    print "#include \"luxel/luxel.h\""
    print "#include <stdio.h>"
    print "#include <stdlib.h>"
    print ""
    print "int main(void)"
    print "{"
}
/^ \* USAGE/ { inside = 1; found = 1; next }
inside && (/^ \*\// || /^ \*$/) { inside = 0 }
inside {
    line = $0
    sub(/^ \*/, "", line)
    sub(/^   /, "", line)
    print "    " line
}
END {
    print "    return 0;"
    print "}"
    if (!found) {
        print header ": no USAGE example" > "/dev/stderr"
        exit 1
    }
}
