; clip_ring (shadow-raster/src/raster.rs at bb2c2a9, before the workaround)
; as LLVM 22.1.2 (rustc 1.95.0) had it after every IR pass of the fat-LTO
; release build: `-C llvm-args=-print-after=safe-stack`, with debug and
; alias metadata removed and the callee renamed. Run:
;   llc -O3 -mtriple=x86_64-unknown-linux-gnu clip_ring.ll -o -
; and look for the scalar spill of ring[0].x (movsd %xmmN, off(%rsp))
; reloaded into the register the loop reads as <a.x, a.y> (see README.md).
target datalayout = "e-m:e-p270:32:32-p271:32:32-p272:64:64-i64:64-i128:128-f80:128-n8:16:32:64-S128"
target triple = "x86_64-unknown-linux-gnu"

declare fastcc void @grow_one(ptr noalias noundef nonnull align 8 dereferenceable(24))

define void @clip_ring(ptr noalias noundef nonnull readonly align 8 captures(none) %0, i64 noundef range(i64 0, 384307168202282326) %1, ptr dead_on_return noalias noundef nonnull readonly align 8 captures(none) dereferenceable(32) %2, ptr noalias noundef nonnull align 8 captures(none) dereferenceable(24) initializes((16, 24)) %3) unnamed_addr #0 {
  %5 = load <2 x double>, ptr %2, align 8
  %6 = getelementptr inbounds nuw i8, ptr %2, i64 16
  %7 = load double, ptr %6, align 8
  %8 = getelementptr inbounds nuw i8, ptr %2, i64 24
  %9 = load double, ptr %8, align 8
  %10 = getelementptr inbounds nuw i8, ptr %3, i64 16
  store i64 0, ptr %10, align 8
  %11 = icmp eq i64 %1, 0
  br i1 %11, label %104, label %12

12:                                               ; preds = %4
  %13 = icmp eq i64 %1, 1
  %14 = load <2 x double>, ptr %0, align 8
  %15 = extractelement <2 x double> %14, i64 1
  %16 = extractelement <2 x double> %14, i64 0
  %17 = getelementptr inbounds nuw i8, ptr %0, i64 16
  %18 = load double, ptr %17, align 8
  br i1 %13, label %19, label %27

19:                                               ; preds = %12
  %20 = fmul <2 x double> %5, %14
  %21 = shufflevector <2 x double> %20, <2 x double> poison, <2 x i32> <i32 1, i32 poison>
  %22 = fadd <2 x double> %20, %21
  %23 = extractelement <2 x double> %22, i64 0
  %24 = fmul double %7, %18
  %25 = fadd double %23, %24
  %26 = fadd double %9, %25
  br label %42

27:                                               ; preds = %12
  %28 = insertelement <2 x double> poison, double %9, i64 0
  %29 = shufflevector <2 x double> %28, <2 x double> poison, <2 x i32> zeroinitializer
  %30 = insertelement <2 x double> poison, double %7, i64 0
  %31 = shufflevector <2 x double> %30, <2 x double> poison, <2 x i32> zeroinitializer
  %32 = mul nuw nsw i64 %1, 24
  br label %105

33:                                               ; preds = %190
  %34 = fmul <2 x double> %5, %14
  %35 = shufflevector <2 x double> %34, <2 x double> poison, <2 x i32> <i32 1, i32 poison>
  %36 = fadd <2 x double> %34, %35
  %37 = extractelement <2 x double> %36, i64 0
  %38 = fmul double %7, %18
  %39 = fadd double %37, %38
  %40 = fadd double %9, %39
  %41 = extractelement <2 x double> %127, i64 0
  br label %42

42:                                               ; preds = %33, %19
  %43 = phi double [ %40, %33 ], [ %26, %19 ]
  %44 = phi double [ %41, %33 ], [ %26, %19 ]
  %45 = phi i64 [ %191, %33 ], [ 0, %19 ]
  %46 = phi double [ %116, %33 ], [ %18, %19 ]
  %47 = phi double [ %113, %33 ], [ %15, %19 ]
  %48 = phi double [ %114, %33 ], [ %16, %19 ]
  %49 = phi <2 x double> [ %112, %33 ], [ %14, %19 ]
  %50 = fcmp ult double %44, 0.000000e+00
  br i1 %50, label %51, label %53

51:                                               ; preds = %42
  %52 = fcmp ult double %43, 0.000000e+00
  br i1 %52, label %104, label %65

53:                                               ; preds = %42
  %54 = load i64, ptr %3, align 8
  %55 = icmp eq i64 %45, %54
  br i1 %55, label %56, label %57

56:                                               ; preds = %53
  tail call fastcc void @grow_one(ptr noalias noundef nonnull align 8 dereferenceable(24) %3)
  br label %57

57:                                               ; preds = %56, %53
  %58 = getelementptr inbounds i8, ptr %3, i64 8
  %59 = load ptr, ptr %58, align 8
  %60 = getelementptr inbounds nuw { double, double, double }, ptr %59, i64 %45
  store <2 x double> %49, ptr %60, align 8
  %61 = getelementptr inbounds nuw i8, ptr %60, i64 16
  store double %46, ptr %61, align 8
  %62 = add i64 %45, 1
  %63 = getelementptr inbounds i8, ptr %3, i64 16
  store i64 %62, ptr %63, align 8
  %64 = fcmp ult double %43, 0.000000e+00
  br i1 %64, label %65, label %104

65:                                               ; preds = %57, %51
  %66 = phi i64 [ %45, %51 ], [ %62, %57 ]
  %67 = fcmp oeq double %48, %16
  br i1 %67, label %68, label %72

68:                                               ; preds = %65
  %69 = fcmp oeq double %47, %15
  br i1 %69, label %70, label %72

70:                                               ; preds = %68
  %71 = fcmp oeq double %46, %18
  br i1 %71, label %77, label %72

72:                                               ; preds = %70, %68, %65
  %73 = phi double [ %48, %65 ], [ %47, %68 ], [ %46, %70 ]
  %74 = phi double [ %16, %65 ], [ %15, %68 ], [ %18, %70 ]
  %75 = fcmp ugt double %73, %74
  br i1 %75, label %77, label %76

76:                                               ; preds = %72
  br label %77

77:                                               ; preds = %76, %72, %70
  %78 = phi double [ %18, %76 ], [ %18, %70 ], [ %46, %72 ]
  %79 = phi double [ %46, %76 ], [ %46, %70 ], [ %18, %72 ]
  %80 = phi double [ %44, %76 ], [ %44, %70 ], [ %43, %72 ]
  %81 = phi double [ %43, %76 ], [ %43, %70 ], [ %44, %72 ]
  %82 = phi <2 x double> [ %49, %76 ], [ %49, %70 ], [ %14, %72 ]
  %83 = phi <2 x double> [ %14, %76 ], [ %14, %70 ], [ %49, %72 ]
  %84 = fsub <2 x double> %83, %82
  %85 = fsub double %78, %79
  %86 = fsub double %80, %81
  %87 = fdiv double %80, %86
  %88 = insertelement <2 x double> poison, double %87, i64 0
  %89 = shufflevector <2 x double> %88, <2 x double> poison, <2 x i32> zeroinitializer
  %90 = fmul <2 x double> %84, %89
  %91 = fmul double %85, %87
  %92 = fadd <2 x double> %82, %90
  %93 = fadd double %79, %91
  %94 = load i64, ptr %3, align 8
  %95 = icmp eq i64 %66, %94
  br i1 %95, label %96, label %97

96:                                               ; preds = %77
  tail call fastcc void @grow_one(ptr noalias noundef nonnull align 8 dereferenceable(24) %3)
  br label %97

97:                                               ; preds = %96, %77
  %98 = getelementptr inbounds i8, ptr %3, i64 8
  %99 = load ptr, ptr %98, align 8
  %100 = getelementptr inbounds nuw { double, double, double }, ptr %99, i64 %66
  store <2 x double> %92, ptr %100, align 8
  %101 = getelementptr inbounds nuw i8, ptr %100, i64 16
  store double %93, ptr %101, align 8
  %102 = add i64 %66, 1
  %103 = getelementptr inbounds i8, ptr %3, i64 16
  store i64 %102, ptr %103, align 8
  br label %104

104:                                              ; preds = %97, %57, %51, %4
  ret void

105:                                              ; preds = %190, %27
  %106 = phi i64 [ %192, %190 ], [ 24, %27 ]
  %107 = phi i64 [ 0, %27 ], [ %191, %190 ]
  %108 = phi double [ %18, %27 ], [ %116, %190 ]
  %109 = phi double [ %16, %27 ], [ %114, %190 ]
  %110 = phi <2 x double> [ %14, %27 ], [ %112, %190 ]
  %111 = getelementptr i8, ptr %0, i64 %106
  %112 = load <2 x double>, ptr %111, align 8
  %113 = extractelement <2 x double> %112, i64 1
  %114 = extractelement <2 x double> %112, i64 0
  %115 = getelementptr i8, ptr %111, i64 16
  %116 = load double, ptr %115, align 8
  %117 = shufflevector <2 x double> %112, <2 x double> %110, <2 x i32> <i32 0, i32 3>
  %118 = fmul <2 x double> %5, %117
  %119 = insertelement <2 x double> %112, double %109, i64 0
  %120 = fmul <2 x double> %5, %119
  %121 = shufflevector <2 x double> %120, <2 x double> poison, <2 x i32> <i32 1, i32 0>
  %122 = fadd <2 x double> %118, %121
  %123 = insertelement <2 x double> poison, double %116, i64 0
  %124 = insertelement <2 x double> %123, double %108, i64 1
  %125 = fmul <2 x double> %31, %124
  %126 = fadd <2 x double> %122, %125
  %127 = fadd <2 x double> %29, %126
  %128 = extractelement <2 x double> %127, i64 1
  %129 = fcmp ult double %128, 0.000000e+00
  br i1 %129, label %130, label %144

130:                                              ; preds = %105
  %131 = extractelement <2 x double> %127, i64 0
  %132 = fcmp ult double %131, 0.000000e+00
  br i1 %132, label %190, label %148

133:                                              ; preds = %147, %144
  %134 = getelementptr inbounds i8, ptr %3, i64 8
  %135 = load ptr, ptr %134, align 8
  %136 = getelementptr inbounds nuw { double, double, double }, ptr %135, i64 %107
  store double %109, ptr %136, align 8
  %137 = getelementptr inbounds nuw i8, ptr %136, i64 8
  %138 = extractelement <2 x double> %110, i64 1
  store double %138, ptr %137, align 8
  %139 = getelementptr inbounds nuw i8, ptr %136, i64 16
  store double %108, ptr %139, align 8
  %140 = add i64 %107, 1
  %141 = getelementptr inbounds i8, ptr %3, i64 16
  store i64 %140, ptr %141, align 8
  %142 = extractelement <2 x double> %127, i64 0
  %143 = fcmp ult double %142, 0.000000e+00
  br i1 %143, label %148, label %190

144:                                              ; preds = %105
  %145 = load i64, ptr %3, align 8
  %146 = icmp eq i64 %107, %145
  br i1 %146, label %147, label %133

147:                                              ; preds = %144
  tail call fastcc void @grow_one(ptr noalias noundef nonnull align 8 dereferenceable(24) %3)
  br label %133

148:                                              ; preds = %133, %130
  %149 = phi i64 [ %107, %130 ], [ %140, %133 ]
  %150 = fcmp oeq double %109, %114
  br i1 %150, label %151, label %156

151:                                              ; preds = %148
  %152 = extractelement <2 x double> %110, i64 1
  %153 = fcmp oeq double %152, %113
  br i1 %153, label %154, label %156

154:                                              ; preds = %151
  %155 = fcmp oeq double %108, %116
  br i1 %155, label %162, label %156

156:                                              ; preds = %154, %151, %148
  %157 = phi double [ %109, %148 ], [ %152, %151 ], [ %108, %154 ]
  %158 = phi double [ %114, %148 ], [ %113, %151 ], [ %116, %154 ]
  %159 = fcmp ugt double %157, %158
  %160 = shufflevector <2 x double> %127, <2 x double> poison, <2 x i32> <i32 1, i32 0>
  br i1 %159, label %162, label %161

161:                                              ; preds = %156
  br label %162

162:                                              ; preds = %161, %156, %154
  %163 = phi double [ %116, %161 ], [ %116, %154 ], [ %108, %156 ]
  %164 = phi double [ %108, %161 ], [ %108, %154 ], [ %116, %156 ]
  %165 = phi <2 x double> [ %110, %161 ], [ %110, %154 ], [ %112, %156 ]
  %166 = phi <2 x double> [ %112, %161 ], [ %112, %154 ], [ %110, %156 ]
  %167 = phi <2 x double> [ %127, %161 ], [ %127, %154 ], [ %160, %156 ]
  %168 = fsub <2 x double> %166, %165
  %169 = fsub double %163, %164
  %170 = extractelement <2 x double> %167, i64 0
  %171 = extractelement <2 x double> %167, i64 1
  %172 = fsub double %171, %170
  %173 = fdiv double %171, %172
  %174 = insertelement <2 x double> poison, double %173, i64 0
  %175 = shufflevector <2 x double> %174, <2 x double> poison, <2 x i32> zeroinitializer
  %176 = fmul <2 x double> %168, %175
  %177 = fmul double %169, %173
  %178 = fadd <2 x double> %165, %176
  %179 = fadd double %164, %177
  %180 = load i64, ptr %3, align 8
  %181 = icmp eq i64 %149, %180
  br i1 %181, label %182, label %183

182:                                              ; preds = %162
  tail call fastcc void @grow_one(ptr noalias noundef nonnull align 8 dereferenceable(24) %3)
  br label %183

183:                                              ; preds = %182, %162
  %184 = getelementptr inbounds i8, ptr %3, i64 8
  %185 = load ptr, ptr %184, align 8
  %186 = getelementptr inbounds nuw { double, double, double }, ptr %185, i64 %149
  store <2 x double> %178, ptr %186, align 8
  %187 = getelementptr inbounds nuw i8, ptr %186, i64 16
  store double %179, ptr %187, align 8
  %188 = add i64 %149, 1
  %189 = getelementptr inbounds i8, ptr %3, i64 16
  store i64 %188, ptr %189, align 8
  br label %190

190:                                              ; preds = %183, %133, %130
  %191 = phi i64 [ %140, %133 ], [ %188, %183 ], [ %107, %130 ]
  %192 = add nuw i64 %106, 24
  %193 = icmp eq i64 %32, %192
  br i1 %193, label %33, label %105
}

attributes #0 = { nonlazybind uwtable "probe-stack"="inline-asm" "target-cpu"="x86-64" }
