#!/usr/bin/perl
# Prints the tests (of the files named) that need the io library, the
# samples or the egofuse program: those whose code -- not their comments --
# names src/io/ or samples/ (an #include of an io header, a sample file's
# path in a string) or EGOFUSE_BIN (the program the test runs).
# The Makefile leaves them out of core-tests (the ARM64 cross run).
# Comments are taken out first, so that a comment naming a path does not
# silently drop a core test from that run; strings and character literals
# (a '"' would otherwise open a string) are kept as they are.
use strict;
use warnings;
local $/;
for my $f (@ARGV) {
    open(my $fh, '<', $f) or die "io_tests.pl: $f: $!\n";
    my $src = <$fh>;
    close($fh);
    $src =~ s{("(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')|/\*.*?\*/|//[^\n]*}{defined $1 ? $1 : ' '}gse;
    print "$f\n" if $src =~ m{src/io/|samples/|EGOFUSE_BIN};
}
