"""``gtecat serve``: the ENI's virtual slaves on a real or virtual NIC (the ESC is drives.esc)."""
