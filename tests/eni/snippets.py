"""Small hand-written ENI texts for reader tests (one idea per test, lines easy to find)."""

from __future__ import annotations


def line_of(text: str, needle: str, nth: int = 0) -> int:
    """1-based line of the ``nth`` occurrence of ``needle`` in ``text``."""
    pos = -1
    for _ in range(nth + 1):
        pos = text.index(needle, pos + 1)
    return text.count("\n", 0, pos) + 1


def entry(index: str, sub: int, bits: int | None, name: str = "", dtype: str = "") -> str:
    parts = [f"<Index>{index}</Index>", f"<SubIndex>{sub}</SubIndex>"]
    if bits is not None:
        parts.append(f"<BitLen>{bits}</BitLen>")
    if name:
        parts.append(f"<Name>{name}</Name>")
    if dtype:
        parts.append(f"<DataType>{dtype}</DataType>")
    return "<Entry>" + "".join(parts) + "</Entry>\n"


def pdo(
    kind: str, index: str, entries: str, name: str = "", sm: int | None = None, fixed: bool = True
) -> str:
    attrs = f' Fixed="{1 if fixed else 0}"' + (f' Sm="{sm}"' if sm is not None else "")
    nm = f"<Name>{name}</Name>\n" if name else ""
    return f"<{kind}{attrs}>\n<Index>{index}</Index>\n{nm}{entries}</{kind}>\n"


def area(tag: str, start: int, length: int) -> str:
    return f"<{tag}><BitStart>{start}</BitStart><BitLength>{length}</BitLength></{tag}>\n"


def slave(
    name: str,
    body: str = "",
    *,
    vendor: str = "#x2",
    product: str = "#x1",
    phys: int | None = None,
    info_extra: str = "",
) -> str:
    ident = ""
    if vendor:
        ident += f"<VendorId>{vendor}</VendorId>\n"
    if product:
        ident += f"<ProductCode>{product}</ProductCode>\n"
    addr = f"<PhysAddr>{phys}</PhysAddr>\n" if phys is not None else ""
    return (
        f"<Slave>\n<Info>\n<Name>{name}</Name>\n{addr}{ident}{info_extra}</Info>\n{body}</Slave>\n"
    )


def process_data(body: str) -> str:
    return f"<ProcessData>\n{body}</ProcessData>\n"


def variable(name: str, offs: int, size: int, dtype: str = "") -> str:
    dt = f"<DataType>{dtype}</DataType>" if dtype else ""
    return (
        f"<Variable><Name>{name}</Name>{dt}<BitSize>{size}</BitSize>"
        f"<BitOffs>{offs}</BitOffs></Variable>\n"
    )


def image(
    inputs: str = "", outputs: str = "", in_size: int | None = None, out_size: int | None = None
) -> str:
    ib = f"<ByteSize>{in_size}</ByteSize>\n" if in_size is not None else ""
    ob = f"<ByteSize>{out_size}</ByteSize>\n" if out_size is not None else ""
    return (
        f"<ProcessImage>\n<Inputs>\n{ib}{inputs}</Inputs>\n"
        f"<Outputs>\n{ob}{outputs}</Outputs>\n</ProcessImage>\n"
    )


def eni(slaves: str, extra: str = "", *, cycle_us: int | None = 1000, root_attrs: str = "") -> str:
    cyc = f"<Cyclic>\n<CycleTime>{cycle_us}</CycleTime>\n</Cyclic>\n" if cycle_us else ""
    return (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        f"<EtherCATConfig{root_attrs}>\n<Config>\n"
        "<Master><Info><Name>test master</Name></Info></Master>\n"
        f"{slaves}{cyc}{extra}</Config>\n</EtherCATConfig>\n"
    )


def servo_slave(
    name: str = "Drive", start_out: int = 0, start_in: int = 0, phys: int | None = None
) -> str:
    """A drive with figure 5-2's mapping, SM-assigned by list."""
    rx = pdo(
        "RxPdo",
        "#x1600",
        entry("#x6040", 0, 16, "Controlword", "UINT")
        + entry("#x607A", 0, 32, "Target position", "DINT"),
        "Outputs",
    )
    tx = pdo(
        "TxPdo",
        "#x1A00",
        entry("#x6041", 0, 16, "Statusword", "UINT")
        + entry("#x6064", 0, 32, "Position actual value", "DINT")
        + entry("#x60FD", 0, 32, "Digital inputs", "UDINT"),
        "Inputs",
    )
    sms = (
        "<Sm2><Type>Outputs</Type><Pdo>#x1600</Pdo></Sm2>\n"
        "<Sm3><Type>Inputs</Type><Pdo>#x1A00</Pdo></Sm3>\n"
    )
    body = process_data(area("Send", start_out, 48) + area("Recv", start_in, 80) + sms + rx + tx)
    return slave(name, body, phys=phys)
