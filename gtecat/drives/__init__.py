"""Virtual EtherCAT slaves: CiA-402 drives, IO, mechanics, object dictionary and CoE."""
