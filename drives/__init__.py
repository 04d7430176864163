"""Virtual EtherCAT slaves: CiA-402 drives, IO slaves, their mechanics, object dictionary and CoE."""
