' A VB.NET module in the field's style (written for the scan test).
Module Module1
    Declare Function GT_Open Lib "gts.dll" (ByVal channel As Short, ByVal param As Short) As Short
    Declare Function GT_AxisOn Lib "gts.dll" (ByVal axis As Short) As Short
    Public Const MC_LIMIT_POSITIVE As Short = 0
    Sub Main()
        Dim rtn As Short = GT_Open(0, 1)  ' GT_CommentedOut(1) is a comment
        rtn = GT_AxisOn(1)
        rtn = GT_ClrSts(1, 1)
    End Sub
End Module
