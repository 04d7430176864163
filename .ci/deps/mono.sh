DEBS="mono-mcs mono-runtime"
