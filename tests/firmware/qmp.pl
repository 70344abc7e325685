#!/usr/bin/perl
# QMP client for the firmware checks: connects to QEMU's QMP unix socket, takes a screendump into
# FILE (PPM) and quits QEMU. Usage: qmp.pl SOCKET FILE. Exit status 0 when QEMU acknowledged the dump.
use strict;
use warnings;
use IO::Socket::UNIX;

my ($path, $file) = @ARGV;
my $s = IO::Socket::UNIX->new(Type => SOCK_STREAM(), Peer => $path) or die "qmp: cannot connect to $path: $!\n";
$SIG{ALRM} = sub { die "qmp: no answer from QEMU\n" };
alarm 10;

sub reply {
  while (my $line = <$s>) {
    next if $line =~ /"event"/;
    return $line;
  }
  die "qmp: connection closed\n";
}

reply();  # greeting
print $s qq({"execute":"qmp_capabilities"}\n);
reply() =~ /"return"/ or die "qmp: capabilities refused\n";
print $s qq({"execute":"screendump","arguments":{"filename":"$file"}}\n);
my $r = reply();
$r =~ /"return"/ or die "qmp: screendump failed: $r";
print $s qq({"execute":"quit"}\n);
exit 0;
