#!/usr/bin/env python3
# Issue 28, "one far copy corrupts a group of instances", on any sdfc binary:
# the scenes of InstancesGpu.OneFarCopyLeavesTheGroupExact (45 spheres, boxes
# or a file() point set on a 1.5 grid and one copy at 1e3 .. 1e30), rendered
# with `sdfc render --view depth` at 64x36, each pixel against the exact first
# hit in float64. Usage: bench/far_copy_check.py path/to/sdfc (run in a scratch
# directory: it writes s.sdf, points.csv and d.pfm there).
import sys, struct, math, subprocess, os
sdfc = sys.argv[1]
W, H = 64, 36
cent = [((i % 9) * 1.5, (i // 9 % 3) * 1.5, (i // 27) * 1.5 - 1.5) for i in range(45)]
def norm(v): l = math.sqrt(sum(x*x for x in v)); return [x/l for x in v]
def cross(a,b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
eye=[6,6,12]; tgt=[6,1,0]
fw=norm([t-e for t,e in zip(tgt,eye)]); right=norm(cross(fw,[0,1,0])); up=cross(right,fw)
th=math.tan(math.radians(45)/2)
def hs(ro,rd,c,r=0.5):
    q=[a-b for a,b in zip(ro,c)]; b=sum(x*y for x,y in zip(q,rd)); cc=sum(x*x for x in q)-r*r; h=b*b-cc
    if cc<=0: return 0
    if b>=0 or h<0: return 1e300
    return cc/(math.sqrt(h)-b)
def hb(ro,rd,c,hh=0.4):
    t0,t1=0,1e300
    for a in range(3):
        if rd[a]==0:
            if abs(ro[a]-c[a])>hh: return 1e300
            continue
        ta=(c[a]-hh-ro[a])/rd[a]; tb=(c[a]+hh-ro[a])/rd[a]
        t0=max(t0,min(ta,tb)); t1=min(t1,max(ta,tb))
    return t0 if t0<=t1 else 1e300
def readpfm(p):
    f=open(p,'rb'); h=f.readline().strip(); w,hh=map(int,f.readline().split()); s=float(f.readline())
    n=3 if h==b'PF' else 1
    d=struct.unpack(('<' if s<0 else '>')+'f'*(w*hh*n), f.read(w*hh*n*4))
    return n,d
for shape in ["sphere","box","file"]:
    for far in ["1e3","3e3","1e6","1e10","1e30"]:
        cs = cent+[(float(far),0,0)]
        s='camera(position: [6, 6, 12], target: [6, 1, 0], fov: 45)\nsun(direction: [-0.4, 0.8, 0.5])\nscene {\n'
        if shape=="file":
            open("points.csv","w").write("".join("%g,%g,%g\n"%c for c in cs))
            s+='  instances(positions: file("points.csv")) { sphere(radius: 0.5) }\n'
        else:
            for c in cs: s+='  translate([%g, %g, %g]) { %s }\n'%(c+("box(size: [0.8, 0.8, 0.8])" if shape=="box" else "sphere(radius: 0.5)",))
        s+='}\n'
        open("s.sdf","w").write(s)
        for attempt in range(4):
            r=subprocess.run(["nice",sdfc,"render","s.sdf","--size","%dx%d"%(W,H),"--spp","1","--view","depth","-o","d.pfm"],capture_output=True)
            if r.returncode==0: break
            print("retry", r.returncode, r.stderr.decode()[-300:], flush=True)
        n,d=readpfm("d.pfm")
        hits=dis=off=0
        for y in range(H):
            for x in range(W):
                nx=2*(x+0.5)/W-1; ny=1-2*(y+0.5)/H
                rd=norm([f+nx*W/H*th*r+ny*th*u for f,r,u in zip(fw,right,up)])
                ex=min((hb if shape=="box" else hs)(eye,rd,c) for c in cs)
                # PFM rows are bottom-up
                v=d[((H-1-y)*W+x)*n]
                hit=v>=0; eh=ex<1e300
                hits+=eh; dis+=hit!=eh
                if hit and eh and abs(v-ex)/ex>1e-4: off+=1
        print(f"{shape} far {far}: exact hits {hits}, hit/miss differ {dis}, depth off >1e-4 rel {off}", flush=True)
