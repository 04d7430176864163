DEBS="mono-mcs mono-runtime libmono-system-data4.0-cil libmono-system-drawing4.0-cil libmono-system-windows-forms4.0-cil"
