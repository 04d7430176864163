"""``gtecat serve``: the ENI's virtual slaves on a real or virtual NIC (ESC: gtecat.drives.esc)."""
