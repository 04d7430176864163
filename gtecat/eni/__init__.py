"""ENI (ETG.2100 XML and Googol INI) configuration model, readers, writer and layout."""
