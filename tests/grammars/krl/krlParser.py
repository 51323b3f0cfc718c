# encoding: utf-8
from antlr4 import *
from io import StringIO
import sys
if sys.version_info[1] > 5:
	from typing import TextIO
else:
	from typing.io import TextIO

def serializedATN():
    return [
        4,1,110,801,2,0,7,0,2,1,7,1,2,2,7,2,2,3,7,3,2,4,7,4,2,5,7,5,2,6,
        7,6,2,7,7,7,2,8,7,8,2,9,7,9,2,10,7,10,2,11,7,11,2,12,7,12,2,13,7,
        13,2,14,7,14,2,15,7,15,2,16,7,16,2,17,7,17,2,18,7,18,2,19,7,19,2,
        20,7,20,2,21,7,21,2,22,7,22,2,23,7,23,2,24,7,24,2,25,7,25,2,26,7,
        26,2,27,7,27,2,28,7,28,2,29,7,29,2,30,7,30,2,31,7,31,2,32,7,32,2,
        33,7,33,2,34,7,34,2,35,7,35,2,36,7,36,2,37,7,37,2,38,7,38,2,39,7,
        39,2,40,7,40,2,41,7,41,2,42,7,42,2,43,7,43,2,44,7,44,2,45,7,45,2,
        46,7,46,2,47,7,47,2,48,7,48,2,49,7,49,2,50,7,50,2,51,7,51,2,52,7,
        52,2,53,7,53,2,54,7,54,2,55,7,55,2,56,7,56,2,57,7,57,2,58,7,58,2,
        59,7,59,2,60,7,60,2,61,7,61,2,62,7,62,1,0,1,0,3,0,129,8,0,1,0,1,
        0,1,1,1,1,1,1,5,1,136,8,1,10,1,12,1,139,9,1,1,2,1,2,3,2,143,8,2,
        1,3,1,3,3,3,147,8,3,1,4,3,4,150,8,4,1,4,1,4,1,4,1,4,1,4,1,4,1,4,
        1,5,1,5,1,6,3,6,162,8,6,1,6,1,6,1,6,1,6,1,6,1,6,1,6,1,6,1,7,1,7,
        1,8,1,8,1,8,3,8,177,8,8,1,8,1,8,1,8,1,8,5,8,183,8,8,10,8,12,8,186,
        9,8,1,9,1,9,1,10,1,10,1,10,1,10,1,10,1,10,1,10,1,10,1,10,1,10,1,
        10,1,10,1,10,1,10,1,10,1,10,5,10,206,8,10,10,10,12,10,209,9,10,1,
        11,1,11,1,11,1,11,1,11,1,12,1,12,3,12,218,8,12,1,13,3,13,221,8,13,
        1,13,1,13,1,13,1,13,1,13,1,13,1,13,1,13,1,13,1,13,5,13,233,8,13,
        10,13,12,13,236,9,13,1,14,3,14,239,8,14,1,14,1,14,1,14,1,14,1,14,
        5,14,246,8,14,10,14,12,14,249,9,14,1,15,1,15,1,16,3,16,254,8,16,
        1,16,1,16,1,16,1,16,1,16,3,16,261,8,16,1,17,1,17,1,17,1,17,1,17,
        3,17,268,8,17,1,18,3,18,271,8,18,1,18,3,18,274,8,18,1,18,3,18,277,
        8,18,1,18,1,18,1,18,1,18,3,18,283,8,18,1,18,3,18,286,8,18,1,19,1,
        19,5,19,290,8,19,10,19,12,19,293,9,19,1,20,1,20,1,20,1,21,1,21,1,
        21,1,21,3,21,302,8,21,1,21,1,21,1,21,1,22,1,22,1,22,5,22,310,8,22,
        10,22,12,22,313,9,22,1,23,1,23,1,23,1,24,1,24,1,24,1,24,5,24,322,
        8,24,10,24,12,24,325,9,24,3,24,327,8,24,1,24,1,24,1,25,1,25,3,25,
        333,8,25,1,26,1,26,1,26,1,27,1,27,1,27,1,27,1,27,1,27,1,27,1,27,
        1,27,1,27,1,27,5,27,349,8,27,10,27,12,27,352,9,27,1,28,1,28,1,28,
        1,28,1,28,1,28,1,28,1,28,1,28,3,28,363,8,28,1,29,1,29,1,29,1,29,
        5,29,369,8,29,10,29,12,29,372,9,29,3,29,374,8,29,1,29,1,29,1,30,
        1,30,3,30,380,8,30,1,31,1,31,1,31,1,32,1,32,1,32,1,32,1,32,1,32,
        1,32,1,32,1,32,1,33,1,33,3,33,396,8,33,1,34,1,34,1,34,1,34,1,34,
        1,34,3,34,404,8,34,3,34,406,8,34,3,34,408,8,34,3,34,410,8,34,3,34,
        412,8,34,1,34,1,34,1,35,1,35,1,36,5,36,419,8,36,10,36,12,36,422,
        9,36,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,
        3,37,436,8,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,
        1,37,1,37,1,37,1,37,1,37,1,37,1,37,3,37,455,8,37,1,37,1,37,1,37,
        1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,
        1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,
        1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,
        3,37,499,8,37,1,37,1,37,1,37,3,37,504,8,37,1,37,1,37,1,37,1,37,1,
        37,1,37,1,37,1,37,1,37,3,37,515,8,37,1,37,1,37,1,37,1,37,1,37,1,
        37,1,37,1,37,1,37,1,37,1,37,1,37,3,37,529,8,37,1,37,1,37,1,37,1,
        37,1,37,3,37,536,8,37,3,37,538,8,37,1,37,1,37,1,37,1,37,1,37,3,37,
        545,8,37,1,37,1,37,1,37,1,37,1,37,3,37,552,8,37,1,37,3,37,555,8,
        37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,3,37,566,8,37,1,
        37,3,37,569,8,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,37,1,
        37,1,37,1,37,1,37,1,37,1,37,3,37,586,8,37,1,37,1,37,1,37,1,37,1,
        37,1,37,1,37,1,37,3,37,596,8,37,1,38,1,38,1,38,1,38,1,38,1,38,5,
        38,604,8,38,10,38,12,38,607,9,38,1,38,1,38,3,38,611,8,38,1,39,1,
        39,1,39,1,39,1,39,3,39,618,8,39,1,40,5,40,621,8,40,10,40,12,40,624,
        9,40,1,40,1,40,1,40,4,40,629,8,40,11,40,12,40,630,1,40,1,40,1,40,
        3,40,636,8,40,1,41,1,41,1,41,1,41,5,41,642,8,41,10,41,12,41,645,
        9,41,1,41,1,41,1,42,1,42,1,42,1,43,1,43,1,43,5,43,655,8,43,10,43,
        12,43,658,9,43,1,44,1,44,1,44,5,44,663,8,44,10,44,12,44,666,9,44,
        1,45,1,45,1,45,1,45,5,45,672,8,45,10,45,12,45,675,9,45,1,46,1,46,
        1,47,1,47,1,47,5,47,682,8,47,10,47,12,47,685,9,47,1,48,1,48,1,48,
        5,48,690,8,48,10,48,12,48,693,9,48,1,49,1,49,1,49,5,49,698,8,49,
        10,49,12,49,701,9,49,1,50,1,50,1,50,5,50,706,8,50,10,50,12,50,709,
        9,50,1,51,1,51,1,51,5,51,714,8,51,10,51,12,51,717,9,51,1,52,1,52,
        1,52,5,52,722,8,52,10,52,12,52,725,9,52,1,53,1,53,1,53,1,53,1,53,
        3,53,732,8,53,1,54,1,54,1,54,1,54,1,54,3,54,739,8,54,1,55,1,55,1,
        55,1,55,5,55,745,8,55,10,55,12,55,748,9,55,1,55,3,55,751,8,55,1,
        55,3,55,754,8,55,1,56,1,56,1,56,1,56,1,57,1,57,1,57,3,57,763,8,57,
        1,57,3,57,766,8,57,1,57,1,57,1,57,3,57,771,8,57,1,57,3,57,774,8,
        57,3,57,776,8,57,1,58,1,58,1,59,1,59,1,60,1,60,3,60,784,8,60,1,60,
        1,60,1,61,1,61,1,61,1,61,1,61,1,61,1,61,1,61,3,61,796,8,61,1,62,
        1,62,1,62,1,62,0,0,63,0,2,4,6,8,10,12,14,16,18,20,22,24,26,28,30,
        32,34,36,38,40,42,44,46,48,50,52,54,56,58,60,62,64,66,68,70,72,74,
        76,78,80,82,84,86,88,90,92,94,96,98,100,102,104,106,108,110,112,
        114,116,118,120,122,124,0,10,1,0,83,84,2,0,33,34,36,36,1,0,41,42,
        1,0,12,17,2,0,29,29,81,81,2,0,30,30,101,101,2,0,24,24,27,27,1,0,
        18,19,1,0,20,21,4,0,31,31,40,40,73,73,86,86,862,0,128,1,0,0,0,2,
        132,1,0,0,0,4,142,1,0,0,0,6,146,1,0,0,0,8,149,1,0,0,0,10,158,1,0,
        0,0,12,161,1,0,0,0,14,171,1,0,0,0,16,173,1,0,0,0,18,187,1,0,0,0,
        20,207,1,0,0,0,22,210,1,0,0,0,24,217,1,0,0,0,26,220,1,0,0,0,28,238,
        1,0,0,0,30,250,1,0,0,0,32,253,1,0,0,0,34,262,1,0,0,0,36,270,1,0,
        0,0,38,291,1,0,0,0,40,294,1,0,0,0,42,297,1,0,0,0,44,306,1,0,0,0,
        46,314,1,0,0,0,48,317,1,0,0,0,50,330,1,0,0,0,52,334,1,0,0,0,54,350,
        1,0,0,0,56,362,1,0,0,0,58,364,1,0,0,0,60,377,1,0,0,0,62,381,1,0,
        0,0,64,384,1,0,0,0,66,393,1,0,0,0,68,397,1,0,0,0,70,415,1,0,0,0,
        72,420,1,0,0,0,74,595,1,0,0,0,76,597,1,0,0,0,78,612,1,0,0,0,80,622,
        1,0,0,0,82,637,1,0,0,0,84,648,1,0,0,0,86,651,1,0,0,0,88,659,1,0,
        0,0,90,667,1,0,0,0,92,676,1,0,0,0,94,678,1,0,0,0,96,686,1,0,0,0,
        98,694,1,0,0,0,100,702,1,0,0,0,102,710,1,0,0,0,104,718,1,0,0,0,106,
        731,1,0,0,0,108,738,1,0,0,0,110,753,1,0,0,0,112,755,1,0,0,0,114,
        775,1,0,0,0,116,777,1,0,0,0,118,779,1,0,0,0,120,781,1,0,0,0,122,
        795,1,0,0,0,124,797,1,0,0,0,126,129,3,16,8,0,127,129,3,2,1,0,128,
        126,1,0,0,0,128,127,1,0,0,0,129,130,1,0,0,0,130,131,5,0,0,1,131,
        1,1,0,0,0,132,137,3,4,2,0,133,136,3,6,3,0,134,136,5,104,0,0,135,
        133,1,0,0,0,135,134,1,0,0,0,136,139,1,0,0,0,137,135,1,0,0,0,137,
        138,1,0,0,0,138,3,1,0,0,0,139,137,1,0,0,0,140,143,3,8,4,0,141,143,
        3,12,6,0,142,140,1,0,0,0,142,141,1,0,0,0,143,5,1,0,0,0,144,147,3,
        8,4,0,145,147,3,12,6,0,146,144,1,0,0,0,146,145,1,0,0,0,147,7,1,0,
        0,0,148,150,5,67,0,0,149,148,1,0,0,0,149,150,1,0,0,0,150,151,1,0,
        0,0,151,152,5,47,0,0,152,153,3,10,5,0,153,154,3,48,24,0,154,155,
        5,104,0,0,155,156,3,52,26,0,156,157,5,53,0,0,157,9,1,0,0,0,158,159,
        5,110,0,0,159,11,1,0,0,0,160,162,5,67,0,0,161,160,1,0,0,0,161,162,
        1,0,0,0,162,163,1,0,0,0,163,164,5,50,0,0,164,165,3,114,57,0,165,
        166,3,14,7,0,166,167,3,48,24,0,167,168,5,104,0,0,168,169,3,52,26,
        0,169,170,5,55,0,0,170,13,1,0,0,0,171,172,5,110,0,0,172,15,1,0,0,
        0,173,174,5,49,0,0,174,176,3,18,9,0,175,177,5,85,0,0,176,175,1,0,
        0,0,176,177,1,0,0,0,177,178,1,0,0,0,178,179,5,104,0,0,179,180,3,
        20,10,0,180,184,5,54,0,0,181,183,5,104,0,0,182,181,1,0,0,0,183,186,
        1,0,0,0,184,182,1,0,0,0,184,185,1,0,0,0,185,17,1,0,0,0,186,184,1,
        0,0,0,187,188,5,110,0,0,188,19,1,0,0,0,189,206,5,104,0,0,190,191,
        3,56,28,0,191,192,5,104,0,0,192,206,1,0,0,0,193,194,3,24,12,0,194,
        195,5,104,0,0,195,206,1,0,0,0,196,197,3,36,18,0,197,198,5,104,0,
        0,198,206,1,0,0,0,199,200,3,22,11,0,200,201,5,104,0,0,201,206,1,
        0,0,0,202,203,3,64,32,0,203,204,5,104,0,0,204,206,1,0,0,0,205,189,
        1,0,0,0,205,190,1,0,0,0,205,193,1,0,0,0,205,196,1,0,0,0,205,199,
        1,0,0,0,205,202,1,0,0,0,206,209,1,0,0,0,207,205,1,0,0,0,207,208,
        1,0,0,0,208,21,1,0,0,0,209,207,1,0,0,0,210,211,5,110,0,0,211,212,
        3,68,34,0,212,213,5,1,0,0,213,214,3,108,54,0,214,23,1,0,0,0,215,
        218,3,26,13,0,216,218,3,28,14,0,217,215,1,0,0,0,217,216,1,0,0,0,
        218,25,1,0,0,0,219,221,5,67,0,0,220,219,1,0,0,0,220,221,1,0,0,0,
        221,222,1,0,0,0,222,223,5,91,0,0,223,224,3,116,58,0,224,225,3,114,
        57,0,225,226,3,66,33,0,226,234,3,38,19,0,227,228,5,2,0,0,228,229,
        3,114,57,0,229,230,3,66,33,0,230,231,3,38,19,0,231,233,1,0,0,0,232,
        227,1,0,0,0,233,236,1,0,0,0,234,232,1,0,0,0,234,235,1,0,0,0,235,
        27,1,0,0,0,236,234,1,0,0,0,237,239,5,67,0,0,238,237,1,0,0,0,238,
        239,1,0,0,0,239,240,1,0,0,0,240,241,5,61,0,0,241,242,3,116,58,0,
        242,247,3,30,15,0,243,244,5,2,0,0,244,246,3,30,15,0,245,243,1,0,
        0,0,246,249,1,0,0,0,247,245,1,0,0,0,247,248,1,0,0,0,248,29,1,0,0,
        0,249,247,1,0,0,0,250,251,5,110,0,0,251,31,1,0,0,0,252,254,5,46,
        0,0,253,252,1,0,0,0,253,254,1,0,0,0,254,260,1,0,0,0,255,256,3,114,
        57,0,256,257,3,66,33,0,257,258,3,38,19,0,258,261,1,0,0,0,259,261,
        3,34,17,0,260,255,1,0,0,0,260,259,1,0,0,0,261,33,1,0,0,0,262,263,
        5,90,0,0,263,264,5,110,0,0,264,267,3,110,55,0,265,266,5,94,0,0,266,
        268,3,110,55,0,267,265,1,0,0,0,267,268,1,0,0,0,268,35,1,0,0,0,269,
        271,5,46,0,0,270,269,1,0,0,0,270,271,1,0,0,0,271,273,1,0,0,0,272,
        274,5,67,0,0,273,272,1,0,0,0,273,274,1,0,0,0,274,276,1,0,0,0,275,
        277,5,43,0,0,276,275,1,0,0,0,276,277,1,0,0,0,277,285,1,0,0,0,278,
        279,3,114,57,0,279,282,3,66,33,0,280,283,3,38,19,0,281,283,3,40,
        20,0,282,280,1,0,0,0,282,281,1,0,0,0,283,286,1,0,0,0,284,286,3,34,
        17,0,285,278,1,0,0,0,285,284,1,0,0,0,286,37,1,0,0,0,287,288,5,2,
        0,0,288,290,3,66,33,0,289,287,1,0,0,0,290,293,1,0,0,0,291,289,1,
        0,0,0,291,292,1,0,0,0,292,39,1,0,0,0,293,291,1,0,0,0,294,295,5,1,
        0,0,295,296,3,108,54,0,296,41,1,0,0,0,297,301,5,3,0,0,298,299,3,
        116,58,0,299,300,5,4,0,0,300,302,1,0,0,0,301,298,1,0,0,0,301,302,
        1,0,0,0,302,303,1,0,0,0,303,304,3,44,22,0,304,305,5,5,0,0,305,43,
        1,0,0,0,306,311,3,46,23,0,307,308,5,2,0,0,308,310,3,46,23,0,309,
        307,1,0,0,0,310,313,1,0,0,0,311,309,1,0,0,0,311,312,1,0,0,0,312,
        45,1,0,0,0,313,311,1,0,0,0,314,315,3,66,33,0,315,316,3,108,54,0,
        316,47,1,0,0,0,317,326,5,6,0,0,318,323,3,50,25,0,319,320,5,2,0,0,
        320,322,3,50,25,0,321,319,1,0,0,0,322,325,1,0,0,0,323,321,1,0,0,
        0,323,324,1,0,0,0,324,327,1,0,0,0,325,323,1,0,0,0,326,318,1,0,0,
        0,326,327,1,0,0,0,327,328,1,0,0,0,328,329,5,7,0,0,329,49,1,0,0,0,
        330,332,3,66,33,0,331,333,3,62,31,0,332,331,1,0,0,0,332,333,1,0,
        0,0,333,51,1,0,0,0,334,335,3,54,27,0,335,336,3,70,35,0,336,53,1,
        0,0,0,337,338,3,56,28,0,338,339,5,104,0,0,339,349,1,0,0,0,340,341,
        3,32,16,0,341,342,5,104,0,0,342,349,1,0,0,0,343,344,5,104,0,0,344,
        349,5,104,0,0,345,346,3,64,32,0,346,347,5,104,0,0,347,349,1,0,0,
        0,348,337,1,0,0,0,348,340,1,0,0,0,348,343,1,0,0,0,348,345,1,0,0,
        0,349,352,1,0,0,0,350,348,1,0,0,0,350,351,1,0,0,0,351,55,1,0,0,0,
        352,350,1,0,0,0,353,354,5,63,0,0,354,355,3,10,5,0,355,356,3,58,29,
        0,356,363,1,0,0,0,357,358,5,64,0,0,358,359,3,114,57,0,359,360,3,
        14,7,0,360,361,3,58,29,0,361,363,1,0,0,0,362,353,1,0,0,0,362,357,
        1,0,0,0,363,57,1,0,0,0,364,373,5,6,0,0,365,370,3,60,30,0,366,367,
        5,2,0,0,367,369,3,60,30,0,368,366,1,0,0,0,369,372,1,0,0,0,370,368,
        1,0,0,0,370,371,1,0,0,0,371,374,1,0,0,0,372,370,1,0,0,0,373,365,
        1,0,0,0,373,374,1,0,0,0,374,375,1,0,0,0,375,376,5,7,0,0,376,59,1,
        0,0,0,377,379,3,114,57,0,378,380,3,62,31,0,379,378,1,0,0,0,379,380,
        1,0,0,0,380,61,1,0,0,0,381,382,5,4,0,0,382,383,5,110,0,0,383,63,
        1,0,0,0,384,385,5,71,0,0,385,386,3,114,57,0,386,387,3,66,33,0,387,
        388,5,74,0,0,388,389,5,8,0,0,389,390,3,18,9,0,390,391,5,9,0,0,391,
        392,3,66,33,0,392,65,1,0,0,0,393,395,5,110,0,0,394,396,3,68,34,0,
        395,394,1,0,0,0,395,396,1,0,0,0,396,67,1,0,0,0,397,411,5,10,0,0,
        398,409,3,90,45,0,399,407,5,2,0,0,400,405,3,90,45,0,401,403,5,2,
        0,0,402,404,3,90,45,0,403,402,1,0,0,0,403,404,1,0,0,0,404,406,1,
        0,0,0,405,401,1,0,0,0,405,406,1,0,0,0,406,408,1,0,0,0,407,400,1,
        0,0,0,407,408,1,0,0,0,408,410,1,0,0,0,409,399,1,0,0,0,409,410,1,
        0,0,0,410,412,1,0,0,0,411,398,1,0,0,0,411,412,1,0,0,0,412,413,1,
        0,0,0,413,414,5,11,0,0,414,69,1,0,0,0,415,416,3,72,36,0,416,71,1,
        0,0,0,417,419,3,74,37,0,418,417,1,0,0,0,419,422,1,0,0,0,420,418,
        1,0,0,0,420,421,1,0,0,0,421,73,1,0,0,0,422,420,1,0,0,0,423,424,5,
        44,0,0,424,596,5,104,0,0,425,426,5,62,0,0,426,596,5,104,0,0,427,
        428,5,66,0,0,428,429,5,110,0,0,429,430,5,1,0,0,430,431,3,90,45,0,
        431,432,5,94,0,0,432,435,3,90,45,0,433,434,5,110,0,0,434,436,3,90,
        45,0,435,433,1,0,0,0,435,436,1,0,0,0,436,437,1,0,0,0,437,438,5,104,
        0,0,438,439,3,72,36,0,439,440,5,56,0,0,440,596,1,0,0,0,441,442,5,
        68,0,0,442,443,5,110,0,0,443,596,5,104,0,0,444,445,5,69,0,0,445,
        596,5,104,0,0,446,447,5,70,0,0,447,448,3,90,45,0,448,449,5,93,0,
        0,449,450,5,104,0,0,450,454,3,72,36,0,451,452,5,52,0,0,452,453,5,
        104,0,0,453,455,3,72,36,0,454,451,1,0,0,0,454,455,1,0,0,0,455,456,
        1,0,0,0,456,457,5,57,0,0,457,458,5,104,0,0,458,596,1,0,0,0,459,460,
        5,77,0,0,460,461,5,104,0,0,461,462,3,72,36,0,462,463,5,58,0,0,463,
        464,5,104,0,0,464,596,1,0,0,0,465,466,5,87,0,0,466,467,5,104,0,0,
        467,468,3,72,36,0,468,469,5,97,0,0,469,470,3,90,45,0,470,471,5,104,
        0,0,471,596,1,0,0,0,472,473,5,92,0,0,473,474,3,90,45,0,474,475,5,
        104,0,0,475,476,3,80,40,0,476,477,5,59,0,0,477,478,5,104,0,0,478,
        596,1,0,0,0,479,480,5,98,0,0,480,481,5,66,0,0,481,482,3,90,45,0,
        482,483,5,104,0,0,483,596,1,0,0,0,484,485,5,98,0,0,485,486,5,89,
        0,0,486,487,3,90,45,0,487,488,5,104,0,0,488,596,1,0,0,0,489,490,
        5,100,0,0,490,491,3,90,45,0,491,492,5,104,0,0,492,493,3,72,36,0,
        493,494,5,60,0,0,494,495,5,104,0,0,495,596,1,0,0,0,496,498,5,88,
        0,0,497,499,3,88,44,0,498,497,1,0,0,0,498,499,1,0,0,0,499,500,1,
        0,0,0,500,596,5,104,0,0,501,503,5,32,0,0,502,504,5,110,0,0,503,502,
        1,0,0,0,503,504,1,0,0,0,504,505,1,0,0,0,505,596,5,104,0,0,506,507,
        3,88,44,0,507,508,5,104,0,0,508,596,1,0,0,0,509,510,5,110,0,0,510,
        511,5,4,0,0,511,596,5,104,0,0,512,596,5,104,0,0,513,515,5,67,0,0,
        514,513,1,0,0,0,514,515,1,0,0,0,515,516,1,0,0,0,516,517,5,72,0,0,
        517,518,5,46,0,0,518,519,3,110,55,0,519,520,5,99,0,0,520,521,3,90,
        45,0,521,522,5,51,0,0,522,523,3,88,44,0,523,524,5,104,0,0,524,596,
        1,0,0,0,525,526,5,72,0,0,526,528,5,110,0,0,527,529,3,110,55,0,528,
        527,1,0,0,0,528,529,1,0,0,0,529,530,1,0,0,0,530,596,5,104,0,0,531,
        532,7,0,0,0,532,537,3,104,52,0,533,535,5,35,0,0,534,536,7,1,0,0,
        535,534,1,0,0,0,535,536,1,0,0,0,536,538,1,0,0,0,537,533,1,0,0,0,
        537,538,1,0,0,0,538,539,1,0,0,0,539,540,5,104,0,0,540,596,1,0,0,
        0,541,542,5,76,0,0,542,544,3,104,52,0,543,545,7,1,0,0,544,543,1,
        0,0,0,544,545,1,0,0,0,545,546,1,0,0,0,546,547,5,104,0,0,547,596,
        1,0,0,0,548,549,5,75,0,0,549,551,3,104,52,0,550,552,7,1,0,0,551,
        550,1,0,0,0,551,552,1,0,0,0,552,554,1,0,0,0,553,555,3,124,62,0,554,
        553,1,0,0,0,554,555,1,0,0,0,555,556,1,0,0,0,556,557,5,104,0,0,557,
        596,1,0,0,0,558,559,7,2,0,0,559,560,3,104,52,0,560,561,5,2,0,0,561,
        565,3,104,52,0,562,563,5,2,0,0,563,564,5,110,0,0,564,566,3,110,55,
        0,565,562,1,0,0,0,565,566,1,0,0,0,566,568,1,0,0,0,567,569,7,1,0,
        0,568,567,1,0,0,0,568,569,1,0,0,0,569,570,1,0,0,0,570,571,5,104,
        0,0,571,596,1,0,0,0,572,573,5,95,0,0,573,574,5,99,0,0,574,575,5,
        110,0,0,575,576,5,1,0,0,576,577,3,90,45,0,577,578,5,45,0,0,578,579,
        5,1,0,0,579,580,3,90,45,0,580,581,5,51,0,0,581,585,3,88,44,0,582,
        583,5,82,0,0,583,584,5,1,0,0,584,586,3,90,45,0,585,582,1,0,0,0,585,
        586,1,0,0,0,586,587,1,0,0,0,587,588,5,104,0,0,588,596,1,0,0,0,589,
        590,3,78,39,0,590,591,5,104,0,0,591,596,1,0,0,0,592,593,3,76,38,
        0,593,594,5,104,0,0,594,596,1,0,0,0,595,423,1,0,0,0,595,425,1,0,
        0,0,595,427,1,0,0,0,595,441,1,0,0,0,595,444,1,0,0,0,595,446,1,0,
        0,0,595,459,1,0,0,0,595,465,1,0,0,0,595,472,1,0,0,0,595,479,1,0,
        0,0,595,484,1,0,0,0,595,489,1,0,0,0,595,496,1,0,0,0,595,501,1,0,
        0,0,595,506,1,0,0,0,595,509,1,0,0,0,595,512,1,0,0,0,595,514,1,0,
        0,0,595,525,1,0,0,0,595,531,1,0,0,0,595,541,1,0,0,0,595,548,1,0,
        0,0,595,558,1,0,0,0,595,572,1,0,0,0,595,589,1,0,0,0,595,592,1,0,
        0,0,596,75,1,0,0,0,597,610,5,26,0,0,598,599,5,110,0,0,599,605,3,
        88,44,0,600,601,5,110,0,0,601,602,5,1,0,0,602,604,3,122,61,0,603,
        600,1,0,0,0,604,607,1,0,0,0,605,603,1,0,0,0,605,606,1,0,0,0,606,
        611,1,0,0,0,607,605,1,0,0,0,608,609,5,110,0,0,609,611,5,110,0,0,
        610,598,1,0,0,0,610,608,1,0,0,0,611,77,1,0,0,0,612,617,5,25,0,0,
        613,614,5,110,0,0,614,618,3,88,44,0,615,616,5,110,0,0,616,618,5,
        110,0,0,617,613,1,0,0,0,617,615,1,0,0,0,618,79,1,0,0,0,619,621,5,
        104,0,0,620,619,1,0,0,0,621,624,1,0,0,0,622,620,1,0,0,0,622,623,
        1,0,0,0,623,628,1,0,0,0,624,622,1,0,0,0,625,626,3,82,41,0,626,627,
        3,72,36,0,627,629,1,0,0,0,628,625,1,0,0,0,629,630,1,0,0,0,630,628,
        1,0,0,0,630,631,1,0,0,0,631,635,1,0,0,0,632,633,3,84,42,0,633,634,
        3,72,36,0,634,636,1,0,0,0,635,632,1,0,0,0,635,636,1,0,0,0,636,81,
        1,0,0,0,637,638,5,37,0,0,638,643,3,90,45,0,639,640,5,2,0,0,640,642,
        3,90,45,0,641,639,1,0,0,0,642,645,1,0,0,0,643,641,1,0,0,0,643,644,
        1,0,0,0,644,646,1,0,0,0,645,643,1,0,0,0,646,647,5,104,0,0,647,83,
        1,0,0,0,648,649,5,48,0,0,649,650,5,104,0,0,650,85,1,0,0,0,651,656,
        3,88,44,0,652,653,5,2,0,0,653,655,3,88,44,0,654,652,1,0,0,0,655,
        658,1,0,0,0,656,654,1,0,0,0,656,657,1,0,0,0,657,87,1,0,0,0,658,656,
        1,0,0,0,659,664,3,90,45,0,660,661,5,1,0,0,661,663,3,90,45,0,662,
        660,1,0,0,0,663,666,1,0,0,0,664,662,1,0,0,0,664,665,1,0,0,0,665,
        89,1,0,0,0,666,664,1,0,0,0,667,673,3,94,47,0,668,669,3,92,46,0,669,
        670,3,94,47,0,670,672,1,0,0,0,671,668,1,0,0,0,672,675,1,0,0,0,673,
        671,1,0,0,0,673,674,1,0,0,0,674,91,1,0,0,0,675,673,1,0,0,0,676,677,
        7,3,0,0,677,93,1,0,0,0,678,683,3,96,48,0,679,680,7,4,0,0,680,682,
        3,96,48,0,681,679,1,0,0,0,682,685,1,0,0,0,683,681,1,0,0,0,683,684,
        1,0,0,0,684,95,1,0,0,0,685,683,1,0,0,0,686,691,3,98,49,0,687,688,
        7,5,0,0,688,690,3,98,49,0,689,687,1,0,0,0,690,693,1,0,0,0,691,689,
        1,0,0,0,691,692,1,0,0,0,692,97,1,0,0,0,693,691,1,0,0,0,694,699,3,
        100,50,0,695,696,7,6,0,0,696,698,3,100,50,0,697,695,1,0,0,0,698,
        701,1,0,0,0,699,697,1,0,0,0,699,700,1,0,0,0,700,99,1,0,0,0,701,699,
        1,0,0,0,702,707,3,102,51,0,703,704,7,7,0,0,704,706,3,102,51,0,705,
        703,1,0,0,0,706,709,1,0,0,0,707,705,1,0,0,0,707,708,1,0,0,0,708,
        101,1,0,0,0,709,707,1,0,0,0,710,715,3,104,52,0,711,712,7,8,0,0,712,
        714,3,104,52,0,713,711,1,0,0,0,714,717,1,0,0,0,715,713,1,0,0,0,715,
        716,1,0,0,0,716,103,1,0,0,0,717,715,1,0,0,0,718,723,3,106,53,0,719,
        720,5,4,0,0,720,722,3,106,53,0,721,719,1,0,0,0,722,725,1,0,0,0,723,
        721,1,0,0,0,723,724,1,0,0,0,724,105,1,0,0,0,725,723,1,0,0,0,726,
        727,5,80,0,0,727,732,3,106,53,0,728,729,5,28,0,0,729,732,3,106,53,
        0,730,732,3,108,54,0,731,726,1,0,0,0,731,728,1,0,0,0,731,730,1,0,
        0,0,732,107,1,0,0,0,733,734,5,18,0,0,734,739,3,108,54,0,735,736,
        5,19,0,0,736,739,3,108,54,0,737,739,3,110,55,0,738,733,1,0,0,0,738,
        735,1,0,0,0,738,737,1,0,0,0,739,109,1,0,0,0,740,754,3,112,56,0,741,
        746,3,66,33,0,742,743,5,22,0,0,743,745,3,66,33,0,744,742,1,0,0,0,
        745,748,1,0,0,0,746,744,1,0,0,0,746,747,1,0,0,0,747,750,1,0,0,0,
        748,746,1,0,0,0,749,751,3,120,60,0,750,749,1,0,0,0,750,751,1,0,0,
        0,751,754,1,0,0,0,752,754,3,122,61,0,753,740,1,0,0,0,753,741,1,0,
        0,0,753,752,1,0,0,0,754,111,1,0,0,0,755,756,5,6,0,0,756,757,3,88,
        44,0,757,758,5,7,0,0,758,113,1,0,0,0,759,765,3,118,59,0,760,762,
        5,10,0,0,761,763,5,109,0,0,762,761,1,0,0,0,762,763,1,0,0,0,763,764,
        1,0,0,0,764,766,5,11,0,0,765,760,1,0,0,0,765,766,1,0,0,0,766,776,
        1,0,0,0,767,773,3,116,58,0,768,770,5,10,0,0,769,771,5,109,0,0,770,
        769,1,0,0,0,770,771,1,0,0,0,771,772,1,0,0,0,772,774,5,11,0,0,773,
        768,1,0,0,0,773,774,1,0,0,0,774,776,1,0,0,0,775,759,1,0,0,0,775,
        767,1,0,0,0,776,115,1,0,0,0,777,778,5,110,0,0,778,117,1,0,0,0,779,
        780,7,9,0,0,780,119,1,0,0,0,781,783,5,6,0,0,782,784,3,86,43,0,783,
        782,1,0,0,0,783,784,1,0,0,0,784,785,1,0,0,0,785,786,5,7,0,0,786,
        121,1,0,0,0,787,796,5,109,0,0,788,796,5,108,0,0,789,796,5,106,0,
        0,790,796,5,107,0,0,791,796,3,42,21,0,792,796,5,96,0,0,793,796,5,
        65,0,0,794,796,3,124,62,0,795,787,1,0,0,0,795,788,1,0,0,0,795,789,
        1,0,0,0,795,790,1,0,0,0,795,791,1,0,0,0,795,792,1,0,0,0,795,793,
        1,0,0,0,795,794,1,0,0,0,796,123,1,0,0,0,797,798,5,23,0,0,798,799,
        5,110,0,0,799,125,1,0,0,0,86,128,135,137,142,146,149,161,176,184,
        205,207,217,220,234,238,247,253,260,267,270,273,276,282,285,291,
        301,311,323,326,332,348,350,362,370,373,379,395,403,405,407,409,
        411,420,435,454,498,503,514,528,535,537,544,551,554,565,568,585,
        595,605,610,617,622,630,635,643,656,664,673,683,691,699,707,715,
        723,731,738,746,750,753,762,765,770,773,775,783,795
    ]

class krlParser ( Parser ):

    grammarFileName = "krl.g4"

    atn = ATNDeserializer().deserialize(serializedATN())

    decisionsToDFA = [ DFA(ds, i) for i, ds in enumerate(atn.decisionToState) ]

    sharedContextCache = PredictionContextCache()

    literalNames = [ "<INVALID>", "'='", "','", "'{'", "':'", "'}'", "'('", 
                     "')'", "'/R1/'", "'..'", "'['", "']'", "'=='", "'<>'", 
                     "'<='", "'>='", "'<'", "'>'", "'+'", "'-'", "'*'", 
                     "'/'", "'.'", "'#'" ]

    symbolicNames = [ "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "<INVALID>", "<INVALID>", "<INVALID>", "<INVALID>", 
                      "AND", "ANIN", "ANOUT", "B_AND", "B_NOT", "B_OR", 
                      "B_EXOR", "BOOL", "BRAKE", "C_DIS", "C_ORI", "C_PTP", 
                      "C_VEL", "CASE", "CAST_FROM", "CAST_TO", "CHAR", "CIRC_REL", 
                      "CIRC", "CONST", "CONTINUE", "DELAY", "DECL", "DEF", 
                      "DEFAULT", "DEFDAT", "DEFFCT", "DO", "ELSE", "END", 
                      "ENDDAT", "ENDFCT", "ENDFOR", "ENDIF", "ENDLOOP", 
                      "ENDSWITCH", "ENDWHILE", "ENUM", "EXIT", "EXT", "EXTFCT", 
                      "FALSE", "FOR", "GLOBAL", "GOTO", "HALT", "IF", "IMPORT", 
                      "INTERRUPT", "INT", "IS", "LIN_REL", "LIN", "LOOP", 
                      "MAXIMUM", "MINIMUM", "NOT", "OR", "PRIO", "PTP_REL", 
                      "PTP", "PUBLIC", "REAL", "REPEAT", "RETURN", "SEC", 
                      "SIGNAL", "STRUC", "SWITCH", "THEN", "TO", "TRIGGER", 
                      "TRUE", "UNTIL", "WAIT", "WHEN", "WHILE", "EXOR", 
                      "HEADERLINE", "WS", "NEWLINE", "LINE_COMMENT", "CHARLITERAL", 
                      "STRINGLITERAL", "FLOATLITERAL", "INTLITERAL", "IDENTIFIER" ]

    RULE_module = 0
    RULE_moduleRoutines = 1
    RULE_mainRoutine = 2
    RULE_subRoutine = 3
    RULE_procedureDefinition = 4
    RULE_procedureName = 5
    RULE_functionDefinition = 6
    RULE_functionName = 7
    RULE_moduleData = 8
    RULE_moduleName = 9
    RULE_dataList = 10
    RULE_arrayInitialisation = 11
    RULE_typeDeclaration = 12
    RULE_structureDefinition = 13
    RULE_enumDefinition = 14
    RULE_enumValue = 15
    RULE_variableDeclaration = 16
    RULE_signalDeclaration = 17
    RULE_variableDeclarationInDataList = 18
    RULE_variableListRest = 19
    RULE_variableInitialisation = 20
    RULE_structLiteral = 21
    RULE_structElementList = 22
    RULE_structElement = 23
    RULE_formalParameters = 24
    RULE_parameter = 25
    RULE_routineBody = 26
    RULE_routineDataSection = 27
    RULE_forwardDeclaration = 28
    RULE_formalParametersWithType = 29
    RULE_parameterWithType = 30
    RULE_parameterCallType = 31
    RULE_importStatement = 32
    RULE_variableName = 33
    RULE_arrayVariableSuffix = 34
    RULE_routineImplementationSection = 35
    RULE_statementList = 36
    RULE_statement = 37
    RULE_analogOutputStatement = 38
    RULE_analogInputStatement = 39
    RULE_switchBlockStatementGroups = 40
    RULE_caseLabel = 41
    RULE_defaultLabel = 42
    RULE_expressionList = 43
    RULE_assignmentExpression = 44
    RULE_expression = 45
    RULE_relationalOp = 46
    RULE_conditionalOrExpression = 47
    RULE_exclusiveOrExpression = 48
    RULE_conditionalAndExpression = 49
    RULE_additiveExpression = 50
    RULE_multiplicativeExpression = 51
    RULE_geometricExpression = 52
    RULE_unaryNotExpression = 53
    RULE_unaryPlusMinuxExpression = 54
    RULE_primary = 55
    RULE_parExpression = 56
    RULE_type_ = 57
    RULE_typeName = 58
    RULE_primitiveType = 59
    RULE_arguments = 60
    RULE_literal = 61
    RULE_enumElement = 62

    ruleNames =  [ "module", "moduleRoutines", "mainRoutine", "subRoutine", 
                   "procedureDefinition", "procedureName", "functionDefinition", 
                   "functionName", "moduleData", "moduleName", "dataList", 
                   "arrayInitialisation", "typeDeclaration", "structureDefinition", 
                   "enumDefinition", "enumValue", "variableDeclaration", 
                   "signalDeclaration", "variableDeclarationInDataList", 
                   "variableListRest", "variableInitialisation", "structLiteral", 
                   "structElementList", "structElement", "formalParameters", 
                   "parameter", "routineBody", "routineDataSection", "forwardDeclaration", 
                   "formalParametersWithType", "parameterWithType", "parameterCallType", 
                   "importStatement", "variableName", "arrayVariableSuffix", 
                   "routineImplementationSection", "statementList", "statement", 
                   "analogOutputStatement", "analogInputStatement", "switchBlockStatementGroups", 
                   "caseLabel", "defaultLabel", "expressionList", "assignmentExpression", 
                   "expression", "relationalOp", "conditionalOrExpression", 
                   "exclusiveOrExpression", "conditionalAndExpression", 
                   "additiveExpression", "multiplicativeExpression", "geometricExpression", 
                   "unaryNotExpression", "unaryPlusMinuxExpression", "primary", 
                   "parExpression", "type_", "typeName", "primitiveType", 
                   "arguments", "literal", "enumElement" ]

    EOF = Token.EOF
    T__0=1
    T__1=2
    T__2=3
    T__3=4
    T__4=5
    T__5=6
    T__6=7
    T__7=8
    T__8=9
    T__9=10
    T__10=11
    T__11=12
    T__12=13
    T__13=14
    T__14=15
    T__15=16
    T__16=17
    T__17=18
    T__18=19
    T__19=20
    T__20=21
    T__21=22
    T__22=23
    AND=24
    ANIN=25
    ANOUT=26
    B_AND=27
    B_NOT=28
    B_OR=29
    B_EXOR=30
    BOOL=31
    BRAKE=32
    C_DIS=33
    C_ORI=34
    C_PTP=35
    C_VEL=36
    CASE=37
    CAST_FROM=38
    CAST_TO=39
    CHAR=40
    CIRC_REL=41
    CIRC=42
    CONST=43
    CONTINUE=44
    DELAY=45
    DECL=46
    DEF=47
    DEFAULT=48
    DEFDAT=49
    DEFFCT=50
    DO=51
    ELSE=52
    END=53
    ENDDAT=54
    ENDFCT=55
    ENDFOR=56
    ENDIF=57
    ENDLOOP=58
    ENDSWITCH=59
    ENDWHILE=60
    ENUM=61
    EXIT=62
    EXT=63
    EXTFCT=64
    FALSE=65
    FOR=66
    GLOBAL=67
    GOTO=68
    HALT=69
    IF=70
    IMPORT=71
    INTERRUPT=72
    INT=73
    IS=74
    LIN_REL=75
    LIN=76
    LOOP=77
    MAXIMUM=78
    MINIMUM=79
    NOT=80
    OR=81
    PRIO=82
    PTP_REL=83
    PTP=84
    PUBLIC=85
    REAL=86
    REPEAT=87
    RETURN=88
    SEC=89
    SIGNAL=90
    STRUC=91
    SWITCH=92
    THEN=93
    TO=94
    TRIGGER=95
    TRUE=96
    UNTIL=97
    WAIT=98
    WHEN=99
    WHILE=100
    EXOR=101
    HEADERLINE=102
    WS=103
    NEWLINE=104
    LINE_COMMENT=105
    CHARLITERAL=106
    STRINGLITERAL=107
    FLOATLITERAL=108
    INTLITERAL=109
    IDENTIFIER=110

    def __init__(self, input:TokenStream, output:TextIO = sys.stdout):
        super().__init__(input, output)
        self.checkVersion("4.13.2")
        self._interp = ParserATNSimulator(self, self.atn, self.decisionsToDFA, self.sharedContextCache)
        self._predicates = None




    class ModuleContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def EOF(self):
            return self.getToken(krlParser.EOF, 0)

        def moduleData(self):
            return self.getTypedRuleContext(krlParser.ModuleDataContext,0)


        def moduleRoutines(self):
            return self.getTypedRuleContext(krlParser.ModuleRoutinesContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_module

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterModule" ):
                listener.enterModule(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitModule" ):
                listener.exitModule(self)




    def module(self):

        localctx = krlParser.ModuleContext(self, self._ctx, self.state)
        self.enterRule(localctx, 0, self.RULE_module)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 128
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [49]:
                self.state = 126
                self.moduleData()
                pass
            elif token in [47, 50, 67]:
                self.state = 127
                self.moduleRoutines()
                pass
            else:
                raise NoViableAltException(self)

            self.state = 130
            self.match(krlParser.EOF)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ModuleRoutinesContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def mainRoutine(self):
            return self.getTypedRuleContext(krlParser.MainRoutineContext,0)


        def subRoutine(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.SubRoutineContext)
            else:
                return self.getTypedRuleContext(krlParser.SubRoutineContext,i)


        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def getRuleIndex(self):
            return krlParser.RULE_moduleRoutines

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterModuleRoutines" ):
                listener.enterModuleRoutines(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitModuleRoutines" ):
                listener.exitModuleRoutines(self)




    def moduleRoutines(self):

        localctx = krlParser.ModuleRoutinesContext(self, self._ctx, self.state)
        self.enterRule(localctx, 2, self.RULE_moduleRoutines)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 132
            self.mainRoutine()
            self.state = 137
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while ((((_la - 47)) & ~0x3f) == 0 and ((1 << (_la - 47)) & 144115188076904457) != 0):
                self.state = 135
                self._errHandler.sync(self)
                token = self._input.LA(1)
                if token in [47, 50, 67]:
                    self.state = 133
                    self.subRoutine()
                    pass
                elif token in [104]:
                    self.state = 134
                    self.match(krlParser.NEWLINE)
                    pass
                else:
                    raise NoViableAltException(self)

                self.state = 139
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class MainRoutineContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def procedureDefinition(self):
            return self.getTypedRuleContext(krlParser.ProcedureDefinitionContext,0)


        def functionDefinition(self):
            return self.getTypedRuleContext(krlParser.FunctionDefinitionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_mainRoutine

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterMainRoutine" ):
                listener.enterMainRoutine(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitMainRoutine" ):
                listener.exitMainRoutine(self)




    def mainRoutine(self):

        localctx = krlParser.MainRoutineContext(self, self._ctx, self.state)
        self.enterRule(localctx, 4, self.RULE_mainRoutine)
        try:
            self.state = 142
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,3,self._ctx)
            if la_ == 1:
                self.enterOuterAlt(localctx, 1)
                self.state = 140
                self.procedureDefinition()
                pass

            elif la_ == 2:
                self.enterOuterAlt(localctx, 2)
                self.state = 141
                self.functionDefinition()
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class SubRoutineContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def procedureDefinition(self):
            return self.getTypedRuleContext(krlParser.ProcedureDefinitionContext,0)


        def functionDefinition(self):
            return self.getTypedRuleContext(krlParser.FunctionDefinitionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_subRoutine

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterSubRoutine" ):
                listener.enterSubRoutine(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitSubRoutine" ):
                listener.exitSubRoutine(self)




    def subRoutine(self):

        localctx = krlParser.SubRoutineContext(self, self._ctx, self.state)
        self.enterRule(localctx, 6, self.RULE_subRoutine)
        try:
            self.state = 146
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,4,self._ctx)
            if la_ == 1:
                self.enterOuterAlt(localctx, 1)
                self.state = 144
                self.procedureDefinition()
                pass

            elif la_ == 2:
                self.enterOuterAlt(localctx, 2)
                self.state = 145
                self.functionDefinition()
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ProcedureDefinitionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def DEF(self):
            return self.getToken(krlParser.DEF, 0)

        def procedureName(self):
            return self.getTypedRuleContext(krlParser.ProcedureNameContext,0)


        def formalParameters(self):
            return self.getTypedRuleContext(krlParser.FormalParametersContext,0)


        def NEWLINE(self):
            return self.getToken(krlParser.NEWLINE, 0)

        def routineBody(self):
            return self.getTypedRuleContext(krlParser.RoutineBodyContext,0)


        def END(self):
            return self.getToken(krlParser.END, 0)

        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_procedureDefinition

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterProcedureDefinition" ):
                listener.enterProcedureDefinition(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitProcedureDefinition" ):
                listener.exitProcedureDefinition(self)




    def procedureDefinition(self):

        localctx = krlParser.ProcedureDefinitionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 8, self.RULE_procedureDefinition)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 149
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==67:
                self.state = 148
                self.match(krlParser.GLOBAL)


            self.state = 151
            self.match(krlParser.DEF)
            self.state = 152
            self.procedureName()
            self.state = 153
            self.formalParameters()
            self.state = 154
            self.match(krlParser.NEWLINE)
            self.state = 155
            self.routineBody()
            self.state = 156
            self.match(krlParser.END)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ProcedureNameContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_procedureName

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterProcedureName" ):
                listener.enterProcedureName(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitProcedureName" ):
                listener.exitProcedureName(self)




    def procedureName(self):

        localctx = krlParser.ProcedureNameContext(self, self._ctx, self.state)
        self.enterRule(localctx, 10, self.RULE_procedureName)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 158
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class FunctionDefinitionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def DEFFCT(self):
            return self.getToken(krlParser.DEFFCT, 0)

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def functionName(self):
            return self.getTypedRuleContext(krlParser.FunctionNameContext,0)


        def formalParameters(self):
            return self.getTypedRuleContext(krlParser.FormalParametersContext,0)


        def NEWLINE(self):
            return self.getToken(krlParser.NEWLINE, 0)

        def routineBody(self):
            return self.getTypedRuleContext(krlParser.RoutineBodyContext,0)


        def ENDFCT(self):
            return self.getToken(krlParser.ENDFCT, 0)

        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_functionDefinition

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterFunctionDefinition" ):
                listener.enterFunctionDefinition(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitFunctionDefinition" ):
                listener.exitFunctionDefinition(self)




    def functionDefinition(self):

        localctx = krlParser.FunctionDefinitionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 12, self.RULE_functionDefinition)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 161
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==67:
                self.state = 160
                self.match(krlParser.GLOBAL)


            self.state = 163
            self.match(krlParser.DEFFCT)
            self.state = 164
            self.type_()
            self.state = 165
            self.functionName()
            self.state = 166
            self.formalParameters()
            self.state = 167
            self.match(krlParser.NEWLINE)
            self.state = 168
            self.routineBody()
            self.state = 169
            self.match(krlParser.ENDFCT)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class FunctionNameContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_functionName

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterFunctionName" ):
                listener.enterFunctionName(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitFunctionName" ):
                listener.exitFunctionName(self)




    def functionName(self):

        localctx = krlParser.FunctionNameContext(self, self._ctx, self.state)
        self.enterRule(localctx, 14, self.RULE_functionName)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 171
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ModuleDataContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def DEFDAT(self):
            return self.getToken(krlParser.DEFDAT, 0)

        def moduleName(self):
            return self.getTypedRuleContext(krlParser.ModuleNameContext,0)


        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def dataList(self):
            return self.getTypedRuleContext(krlParser.DataListContext,0)


        def ENDDAT(self):
            return self.getToken(krlParser.ENDDAT, 0)

        def PUBLIC(self):
            return self.getToken(krlParser.PUBLIC, 0)

        def getRuleIndex(self):
            return krlParser.RULE_moduleData

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterModuleData" ):
                listener.enterModuleData(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitModuleData" ):
                listener.exitModuleData(self)




    def moduleData(self):

        localctx = krlParser.ModuleDataContext(self, self._ctx, self.state)
        self.enterRule(localctx, 16, self.RULE_moduleData)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 173
            self.match(krlParser.DEFDAT)
            self.state = 174
            self.moduleName()
            self.state = 176
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==85:
                self.state = 175
                self.match(krlParser.PUBLIC)


            self.state = 178
            self.match(krlParser.NEWLINE)
            self.state = 179
            self.dataList()
            self.state = 180
            self.match(krlParser.ENDDAT)
            self.state = 184
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==104:
                self.state = 181
                self.match(krlParser.NEWLINE)
                self.state = 186
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ModuleNameContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_moduleName

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterModuleName" ):
                listener.enterModuleName(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitModuleName" ):
                listener.exitModuleName(self)




    def moduleName(self):

        localctx = krlParser.ModuleNameContext(self, self._ctx, self.state)
        self.enterRule(localctx, 18, self.RULE_moduleName)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 187
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class DataListContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def forwardDeclaration(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ForwardDeclarationContext)
            else:
                return self.getTypedRuleContext(krlParser.ForwardDeclarationContext,i)


        def typeDeclaration(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.TypeDeclarationContext)
            else:
                return self.getTypedRuleContext(krlParser.TypeDeclarationContext,i)


        def variableDeclarationInDataList(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableDeclarationInDataListContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableDeclarationInDataListContext,i)


        def arrayInitialisation(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ArrayInitialisationContext)
            else:
                return self.getTypedRuleContext(krlParser.ArrayInitialisationContext,i)


        def importStatement(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ImportStatementContext)
            else:
                return self.getTypedRuleContext(krlParser.ImportStatementContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_dataList

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterDataList" ):
                listener.enterDataList(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitDataList" ):
                listener.exitDataList(self)




    def dataList(self):

        localctx = krlParser.DataListContext(self, self._ctx, self.state)
        self.enterRule(localctx, 20, self.RULE_dataList)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 207
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while (((_la) & ~0x3f) == 0 and ((1 << _la) & -6917448761144770560) != 0) or ((((_la - 64)) & ~0x3f) == 0 and ((1 << (_la - 64)) & 71468461326985) != 0):
                self.state = 205
                self._errHandler.sync(self)
                la_ = self._interp.adaptivePredict(self._input,9,self._ctx)
                if la_ == 1:
                    self.state = 189
                    self.match(krlParser.NEWLINE)
                    pass

                elif la_ == 2:
                    self.state = 190
                    self.forwardDeclaration()
                    self.state = 191
                    self.match(krlParser.NEWLINE)
                    pass

                elif la_ == 3:
                    self.state = 193
                    self.typeDeclaration()
                    self.state = 194
                    self.match(krlParser.NEWLINE)
                    pass

                elif la_ == 4:
                    self.state = 196
                    self.variableDeclarationInDataList()
                    self.state = 197
                    self.match(krlParser.NEWLINE)
                    pass

                elif la_ == 5:
                    self.state = 199
                    self.arrayInitialisation()
                    self.state = 200
                    self.match(krlParser.NEWLINE)
                    pass

                elif la_ == 6:
                    self.state = 202
                    self.importStatement()
                    self.state = 203
                    self.match(krlParser.NEWLINE)
                    pass


                self.state = 209
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ArrayInitialisationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def arrayVariableSuffix(self):
            return self.getTypedRuleContext(krlParser.ArrayVariableSuffixContext,0)


        def unaryPlusMinuxExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryPlusMinuxExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_arrayInitialisation

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterArrayInitialisation" ):
                listener.enterArrayInitialisation(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitArrayInitialisation" ):
                listener.exitArrayInitialisation(self)




    def arrayInitialisation(self):

        localctx = krlParser.ArrayInitialisationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 22, self.RULE_arrayInitialisation)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 210
            self.match(krlParser.IDENTIFIER)
            self.state = 211
            self.arrayVariableSuffix()
            self.state = 212
            self.match(krlParser.T__0)
            self.state = 213
            self.unaryPlusMinuxExpression()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class TypeDeclarationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def structureDefinition(self):
            return self.getTypedRuleContext(krlParser.StructureDefinitionContext,0)


        def enumDefinition(self):
            return self.getTypedRuleContext(krlParser.EnumDefinitionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_typeDeclaration

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterTypeDeclaration" ):
                listener.enterTypeDeclaration(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitTypeDeclaration" ):
                listener.exitTypeDeclaration(self)




    def typeDeclaration(self):

        localctx = krlParser.TypeDeclarationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 24, self.RULE_typeDeclaration)
        try:
            self.state = 217
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,11,self._ctx)
            if la_ == 1:
                self.enterOuterAlt(localctx, 1)
                self.state = 215
                self.structureDefinition()
                pass

            elif la_ == 2:
                self.enterOuterAlt(localctx, 2)
                self.state = 216
                self.enumDefinition()
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StructureDefinitionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def STRUC(self):
            return self.getToken(krlParser.STRUC, 0)

        def typeName(self):
            return self.getTypedRuleContext(krlParser.TypeNameContext,0)


        def type_(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.Type_Context)
            else:
                return self.getTypedRuleContext(krlParser.Type_Context,i)


        def variableName(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableNameContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableNameContext,i)


        def variableListRest(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableListRestContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableListRestContext,i)


        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_structureDefinition

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStructureDefinition" ):
                listener.enterStructureDefinition(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStructureDefinition" ):
                listener.exitStructureDefinition(self)




    def structureDefinition(self):

        localctx = krlParser.StructureDefinitionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 26, self.RULE_structureDefinition)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 220
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==67:
                self.state = 219
                self.match(krlParser.GLOBAL)


            self.state = 222
            self.match(krlParser.STRUC)
            self.state = 223
            self.typeName()
            self.state = 224
            self.type_()
            self.state = 225
            self.variableName()
            self.state = 226
            self.variableListRest()
            self.state = 234
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==2:
                self.state = 227
                self.match(krlParser.T__1)
                self.state = 228
                self.type_()
                self.state = 229
                self.variableName()
                self.state = 230
                self.variableListRest()
                self.state = 236
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class EnumDefinitionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def ENUM(self):
            return self.getToken(krlParser.ENUM, 0)

        def typeName(self):
            return self.getTypedRuleContext(krlParser.TypeNameContext,0)


        def enumValue(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.EnumValueContext)
            else:
                return self.getTypedRuleContext(krlParser.EnumValueContext,i)


        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_enumDefinition

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterEnumDefinition" ):
                listener.enterEnumDefinition(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitEnumDefinition" ):
                listener.exitEnumDefinition(self)




    def enumDefinition(self):

        localctx = krlParser.EnumDefinitionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 28, self.RULE_enumDefinition)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 238
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==67:
                self.state = 237
                self.match(krlParser.GLOBAL)


            self.state = 240
            self.match(krlParser.ENUM)
            self.state = 241
            self.typeName()
            self.state = 242
            self.enumValue()
            self.state = 247
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==2:
                self.state = 243
                self.match(krlParser.T__1)
                self.state = 244
                self.enumValue()
                self.state = 249
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class EnumValueContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_enumValue

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterEnumValue" ):
                listener.enterEnumValue(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitEnumValue" ):
                listener.exitEnumValue(self)




    def enumValue(self):

        localctx = krlParser.EnumValueContext(self, self._ctx, self.state)
        self.enterRule(localctx, 30, self.RULE_enumValue)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 250
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class VariableDeclarationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def variableName(self):
            return self.getTypedRuleContext(krlParser.VariableNameContext,0)


        def variableListRest(self):
            return self.getTypedRuleContext(krlParser.VariableListRestContext,0)


        def signalDeclaration(self):
            return self.getTypedRuleContext(krlParser.SignalDeclarationContext,0)


        def DECL(self):
            return self.getToken(krlParser.DECL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_variableDeclaration

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterVariableDeclaration" ):
                listener.enterVariableDeclaration(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitVariableDeclaration" ):
                listener.exitVariableDeclaration(self)




    def variableDeclaration(self):

        localctx = krlParser.VariableDeclarationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 32, self.RULE_variableDeclaration)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 253
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==46:
                self.state = 252
                self.match(krlParser.DECL)


            self.state = 260
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [31, 40, 73, 86, 110]:
                self.state = 255
                self.type_()
                self.state = 256
                self.variableName()
                self.state = 257
                self.variableListRest()
                pass
            elif token in [90]:
                self.state = 259
                self.signalDeclaration()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class SignalDeclarationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def SIGNAL(self):
            return self.getToken(krlParser.SIGNAL, 0)

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def primary(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.PrimaryContext)
            else:
                return self.getTypedRuleContext(krlParser.PrimaryContext,i)


        def TO(self):
            return self.getToken(krlParser.TO, 0)

        def getRuleIndex(self):
            return krlParser.RULE_signalDeclaration

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterSignalDeclaration" ):
                listener.enterSignalDeclaration(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitSignalDeclaration" ):
                listener.exitSignalDeclaration(self)




    def signalDeclaration(self):

        localctx = krlParser.SignalDeclarationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 34, self.RULE_signalDeclaration)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 262
            self.match(krlParser.SIGNAL)
            self.state = 263
            self.match(krlParser.IDENTIFIER)
            self.state = 264
            self.primary()
            self.state = 267
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==94:
                self.state = 265
                self.match(krlParser.TO)
                self.state = 266
                self.primary()


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class VariableDeclarationInDataListContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def variableName(self):
            return self.getTypedRuleContext(krlParser.VariableNameContext,0)


        def signalDeclaration(self):
            return self.getTypedRuleContext(krlParser.SignalDeclarationContext,0)


        def DECL(self):
            return self.getToken(krlParser.DECL, 0)

        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def CONST(self):
            return self.getToken(krlParser.CONST, 0)

        def variableListRest(self):
            return self.getTypedRuleContext(krlParser.VariableListRestContext,0)


        def variableInitialisation(self):
            return self.getTypedRuleContext(krlParser.VariableInitialisationContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_variableDeclarationInDataList

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterVariableDeclarationInDataList" ):
                listener.enterVariableDeclarationInDataList(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitVariableDeclarationInDataList" ):
                listener.exitVariableDeclarationInDataList(self)




    def variableDeclarationInDataList(self):

        localctx = krlParser.VariableDeclarationInDataListContext(self, self._ctx, self.state)
        self.enterRule(localctx, 36, self.RULE_variableDeclarationInDataList)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 270
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==46:
                self.state = 269
                self.match(krlParser.DECL)


            self.state = 273
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==67:
                self.state = 272
                self.match(krlParser.GLOBAL)


            self.state = 276
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==43:
                self.state = 275
                self.match(krlParser.CONST)


            self.state = 285
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [31, 40, 73, 86, 110]:
                self.state = 278
                self.type_()
                self.state = 279
                self.variableName()
                self.state = 282
                self._errHandler.sync(self)
                token = self._input.LA(1)
                if token in [2, 104]:
                    self.state = 280
                    self.variableListRest()
                    pass
                elif token in [1]:
                    self.state = 281
                    self.variableInitialisation()
                    pass
                else:
                    raise NoViableAltException(self)

                pass
            elif token in [90]:
                self.state = 284
                self.signalDeclaration()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class VariableListRestContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def variableName(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableNameContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableNameContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_variableListRest

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterVariableListRest" ):
                listener.enterVariableListRest(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitVariableListRest" ):
                listener.exitVariableListRest(self)




    def variableListRest(self):

        localctx = krlParser.VariableListRestContext(self, self._ctx, self.state)
        self.enterRule(localctx, 38, self.RULE_variableListRest)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 291
            self._errHandler.sync(self)
            _alt = self._interp.adaptivePredict(self._input,24,self._ctx)
            while _alt!=2 and _alt!=ATN.INVALID_ALT_NUMBER:
                if _alt==1:
                    self.state = 287
                    self.match(krlParser.T__1)
                    self.state = 288
                    self.variableName() 
                self.state = 293
                self._errHandler.sync(self)
                _alt = self._interp.adaptivePredict(self._input,24,self._ctx)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class VariableInitialisationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def unaryPlusMinuxExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryPlusMinuxExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_variableInitialisation

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterVariableInitialisation" ):
                listener.enterVariableInitialisation(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitVariableInitialisation" ):
                listener.exitVariableInitialisation(self)




    def variableInitialisation(self):

        localctx = krlParser.VariableInitialisationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 40, self.RULE_variableInitialisation)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 294
            self.match(krlParser.T__0)
            self.state = 295
            self.unaryPlusMinuxExpression()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StructLiteralContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def structElementList(self):
            return self.getTypedRuleContext(krlParser.StructElementListContext,0)


        def typeName(self):
            return self.getTypedRuleContext(krlParser.TypeNameContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_structLiteral

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStructLiteral" ):
                listener.enterStructLiteral(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStructLiteral" ):
                listener.exitStructLiteral(self)




    def structLiteral(self):

        localctx = krlParser.StructLiteralContext(self, self._ctx, self.state)
        self.enterRule(localctx, 42, self.RULE_structLiteral)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 297
            self.match(krlParser.T__2)
            self.state = 301
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,25,self._ctx)
            if la_ == 1:
                self.state = 298
                self.typeName()
                self.state = 299
                self.match(krlParser.T__3)


            self.state = 303
            self.structElementList()
            self.state = 304
            self.match(krlParser.T__4)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StructElementListContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def structElement(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.StructElementContext)
            else:
                return self.getTypedRuleContext(krlParser.StructElementContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_structElementList

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStructElementList" ):
                listener.enterStructElementList(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStructElementList" ):
                listener.exitStructElementList(self)




    def structElementList(self):

        localctx = krlParser.StructElementListContext(self, self._ctx, self.state)
        self.enterRule(localctx, 44, self.RULE_structElementList)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 306
            self.structElement()
            self.state = 311
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==2:
                self.state = 307
                self.match(krlParser.T__1)
                self.state = 308
                self.structElement()
                self.state = 313
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StructElementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def variableName(self):
            return self.getTypedRuleContext(krlParser.VariableNameContext,0)


        def unaryPlusMinuxExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryPlusMinuxExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_structElement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStructElement" ):
                listener.enterStructElement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStructElement" ):
                listener.exitStructElement(self)




    def structElement(self):

        localctx = krlParser.StructElementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 46, self.RULE_structElement)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 314
            self.variableName()
            self.state = 315
            self.unaryPlusMinuxExpression()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class FormalParametersContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def parameter(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ParameterContext)
            else:
                return self.getTypedRuleContext(krlParser.ParameterContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_formalParameters

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterFormalParameters" ):
                listener.enterFormalParameters(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitFormalParameters" ):
                listener.exitFormalParameters(self)




    def formalParameters(self):

        localctx = krlParser.FormalParametersContext(self, self._ctx, self.state)
        self.enterRule(localctx, 48, self.RULE_formalParameters)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 317
            self.match(krlParser.T__5)
            self.state = 326
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==110:
                self.state = 318
                self.parameter()
                self.state = 323
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                while _la==2:
                    self.state = 319
                    self.match(krlParser.T__1)
                    self.state = 320
                    self.parameter()
                    self.state = 325
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)



            self.state = 328
            self.match(krlParser.T__6)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ParameterContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def variableName(self):
            return self.getTypedRuleContext(krlParser.VariableNameContext,0)


        def parameterCallType(self):
            return self.getTypedRuleContext(krlParser.ParameterCallTypeContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_parameter

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterParameter" ):
                listener.enterParameter(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitParameter" ):
                listener.exitParameter(self)




    def parameter(self):

        localctx = krlParser.ParameterContext(self, self._ctx, self.state)
        self.enterRule(localctx, 50, self.RULE_parameter)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 330
            self.variableName()
            self.state = 332
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==4:
                self.state = 331
                self.parameterCallType()


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class RoutineBodyContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def routineDataSection(self):
            return self.getTypedRuleContext(krlParser.RoutineDataSectionContext,0)


        def routineImplementationSection(self):
            return self.getTypedRuleContext(krlParser.RoutineImplementationSectionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_routineBody

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterRoutineBody" ):
                listener.enterRoutineBody(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitRoutineBody" ):
                listener.exitRoutineBody(self)




    def routineBody(self):

        localctx = krlParser.RoutineBodyContext(self, self._ctx, self.state)
        self.enterRule(localctx, 52, self.RULE_routineBody)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 334
            self.routineDataSection()
            self.state = 335
            self.routineImplementationSection()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class RoutineDataSectionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def forwardDeclaration(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ForwardDeclarationContext)
            else:
                return self.getTypedRuleContext(krlParser.ForwardDeclarationContext,i)


        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def variableDeclaration(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableDeclarationContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableDeclarationContext,i)


        def importStatement(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ImportStatementContext)
            else:
                return self.getTypedRuleContext(krlParser.ImportStatementContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_routineDataSection

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterRoutineDataSection" ):
                listener.enterRoutineDataSection(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitRoutineDataSection" ):
                listener.exitRoutineDataSection(self)




    def routineDataSection(self):

        localctx = krlParser.RoutineDataSectionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 54, self.RULE_routineDataSection)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 350
            self._errHandler.sync(self)
            _alt = self._interp.adaptivePredict(self._input,31,self._ctx)
            while _alt!=2 and _alt!=ATN.INVALID_ALT_NUMBER:
                if _alt==1:
                    self.state = 348
                    self._errHandler.sync(self)
                    token = self._input.LA(1)
                    if token in [63, 64]:
                        self.state = 337
                        self.forwardDeclaration()
                        self.state = 338
                        self.match(krlParser.NEWLINE)
                        pass
                    elif token in [31, 40, 46, 73, 86, 90, 110]:
                        self.state = 340
                        self.variableDeclaration()
                        self.state = 341
                        self.match(krlParser.NEWLINE)
                        pass
                    elif token in [104]:
                        self.state = 343
                        self.match(krlParser.NEWLINE)
                        self.state = 344
                        self.match(krlParser.NEWLINE)
                        pass
                    elif token in [71]:
                        self.state = 345
                        self.importStatement()
                        self.state = 346
                        self.match(krlParser.NEWLINE)
                        pass
                    else:
                        raise NoViableAltException(self)
             
                self.state = 352
                self._errHandler.sync(self)
                _alt = self._interp.adaptivePredict(self._input,31,self._ctx)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ForwardDeclarationContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def EXT(self):
            return self.getToken(krlParser.EXT, 0)

        def procedureName(self):
            return self.getTypedRuleContext(krlParser.ProcedureNameContext,0)


        def formalParametersWithType(self):
            return self.getTypedRuleContext(krlParser.FormalParametersWithTypeContext,0)


        def EXTFCT(self):
            return self.getToken(krlParser.EXTFCT, 0)

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def functionName(self):
            return self.getTypedRuleContext(krlParser.FunctionNameContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_forwardDeclaration

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterForwardDeclaration" ):
                listener.enterForwardDeclaration(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitForwardDeclaration" ):
                listener.exitForwardDeclaration(self)




    def forwardDeclaration(self):

        localctx = krlParser.ForwardDeclarationContext(self, self._ctx, self.state)
        self.enterRule(localctx, 56, self.RULE_forwardDeclaration)
        try:
            self.state = 362
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [63]:
                self.enterOuterAlt(localctx, 1)
                self.state = 353
                self.match(krlParser.EXT)
                self.state = 354
                self.procedureName()
                self.state = 355
                self.formalParametersWithType()
                pass
            elif token in [64]:
                self.enterOuterAlt(localctx, 2)
                self.state = 357
                self.match(krlParser.EXTFCT)
                self.state = 358
                self.type_()
                self.state = 359
                self.functionName()
                self.state = 360
                self.formalParametersWithType()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class FormalParametersWithTypeContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def parameterWithType(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ParameterWithTypeContext)
            else:
                return self.getTypedRuleContext(krlParser.ParameterWithTypeContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_formalParametersWithType

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterFormalParametersWithType" ):
                listener.enterFormalParametersWithType(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitFormalParametersWithType" ):
                listener.exitFormalParametersWithType(self)




    def formalParametersWithType(self):

        localctx = krlParser.FormalParametersWithTypeContext(self, self._ctx, self.state)
        self.enterRule(localctx, 58, self.RULE_formalParametersWithType)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 364
            self.match(krlParser.T__5)
            self.state = 373
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==31 or _la==40 or ((((_la - 73)) & ~0x3f) == 0 and ((1 << (_la - 73)) & 137438961665) != 0):
                self.state = 365
                self.parameterWithType()
                self.state = 370
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                while _la==2:
                    self.state = 366
                    self.match(krlParser.T__1)
                    self.state = 367
                    self.parameterWithType()
                    self.state = 372
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)



            self.state = 375
            self.match(krlParser.T__6)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ParameterWithTypeContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def parameterCallType(self):
            return self.getTypedRuleContext(krlParser.ParameterCallTypeContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_parameterWithType

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterParameterWithType" ):
                listener.enterParameterWithType(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitParameterWithType" ):
                listener.exitParameterWithType(self)




    def parameterWithType(self):

        localctx = krlParser.ParameterWithTypeContext(self, self._ctx, self.state)
        self.enterRule(localctx, 60, self.RULE_parameterWithType)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 377
            self.type_()
            self.state = 379
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==4:
                self.state = 378
                self.parameterCallType()


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ParameterCallTypeContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_parameterCallType

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterParameterCallType" ):
                listener.enterParameterCallType(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitParameterCallType" ):
                listener.exitParameterCallType(self)




    def parameterCallType(self):

        localctx = krlParser.ParameterCallTypeContext(self, self._ctx, self.state)
        self.enterRule(localctx, 62, self.RULE_parameterCallType)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 381
            self.match(krlParser.T__3)
            self.state = 382
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ImportStatementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IMPORT(self):
            return self.getToken(krlParser.IMPORT, 0)

        def type_(self):
            return self.getTypedRuleContext(krlParser.Type_Context,0)


        def variableName(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableNameContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableNameContext,i)


        def IS(self):
            return self.getToken(krlParser.IS, 0)

        def moduleName(self):
            return self.getTypedRuleContext(krlParser.ModuleNameContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_importStatement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterImportStatement" ):
                listener.enterImportStatement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitImportStatement" ):
                listener.exitImportStatement(self)




    def importStatement(self):

        localctx = krlParser.ImportStatementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 64, self.RULE_importStatement)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 384
            self.match(krlParser.IMPORT)
            self.state = 385
            self.type_()
            self.state = 386
            self.variableName()
            self.state = 387
            self.match(krlParser.IS)
            self.state = 388
            self.match(krlParser.T__7)
            self.state = 389
            self.moduleName()
            self.state = 390
            self.match(krlParser.T__8)
            self.state = 391
            self.variableName()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class VariableNameContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def arrayVariableSuffix(self):
            return self.getTypedRuleContext(krlParser.ArrayVariableSuffixContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_variableName

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterVariableName" ):
                listener.enterVariableName(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitVariableName" ):
                listener.exitVariableName(self)




    def variableName(self):

        localctx = krlParser.VariableNameContext(self, self._ctx, self.state)
        self.enterRule(localctx, 66, self.RULE_variableName)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 393
            self.match(krlParser.IDENTIFIER)
            self.state = 395
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==10:
                self.state = 394
                self.arrayVariableSuffix()


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ArrayVariableSuffixContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def expression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_arrayVariableSuffix

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterArrayVariableSuffix" ):
                listener.enterArrayVariableSuffix(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitArrayVariableSuffix" ):
                listener.exitArrayVariableSuffix(self)




    def arrayVariableSuffix(self):

        localctx = krlParser.ArrayVariableSuffixContext(self, self._ctx, self.state)
        self.enterRule(localctx, 68, self.RULE_arrayVariableSuffix)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 397
            self.match(krlParser.T__9)
            self.state = 411
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if (((_la) & ~0x3f) == 0 and ((1 << _la) & 277610568) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868438529) != 0):
                self.state = 398
                self.expression()
                self.state = 409
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==2:
                    self.state = 399
                    self.match(krlParser.T__1)
                    self.state = 407
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)
                    if (((_la) & ~0x3f) == 0 and ((1 << _la) & 277610568) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868438529) != 0):
                        self.state = 400
                        self.expression()
                        self.state = 405
                        self._errHandler.sync(self)
                        _la = self._input.LA(1)
                        if _la==2:
                            self.state = 401
                            self.match(krlParser.T__1)
                            self.state = 403
                            self._errHandler.sync(self)
                            _la = self._input.LA(1)
                            if (((_la) & ~0x3f) == 0 and ((1 << _la) & 277610568) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868438529) != 0):
                                self.state = 402
                                self.expression()










            self.state = 413
            self.match(krlParser.T__10)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class RoutineImplementationSectionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def statementList(self):
            return self.getTypedRuleContext(krlParser.StatementListContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_routineImplementationSection

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterRoutineImplementationSection" ):
                listener.enterRoutineImplementationSection(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitRoutineImplementationSection" ):
                listener.exitRoutineImplementationSection(self)




    def routineImplementationSection(self):

        localctx = krlParser.RoutineImplementationSectionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 70, self.RULE_routineImplementationSection)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 415
            self.statementList()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StatementListContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def statement(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.StatementContext)
            else:
                return self.getTypedRuleContext(krlParser.StatementContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_statementList

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStatementList" ):
                listener.enterStatementList(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStatementList" ):
                listener.exitStatementList(self)




    def statementList(self):

        localctx = krlParser.StatementListContext(self, self._ctx, self.state)
        self.enterRule(localctx, 72, self.RULE_statementList)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 420
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while (((_la) & ~0x3f) == 0 and ((1 << _la) & 4611710212356440136) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68765795261631) != 0):
                self.state = 417
                self.statement()
                self.state = 422
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class StatementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def CONTINUE(self):
            return self.getToken(krlParser.CONTINUE, 0)

        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def EXIT(self):
            return self.getToken(krlParser.EXIT, 0)

        def FOR(self):
            return self.getToken(krlParser.FOR, 0)

        def IDENTIFIER(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.IDENTIFIER)
            else:
                return self.getToken(krlParser.IDENTIFIER, i)

        def expression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ExpressionContext,i)


        def TO(self):
            return self.getToken(krlParser.TO, 0)

        def statementList(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.StatementListContext)
            else:
                return self.getTypedRuleContext(krlParser.StatementListContext,i)


        def ENDFOR(self):
            return self.getToken(krlParser.ENDFOR, 0)

        def GOTO(self):
            return self.getToken(krlParser.GOTO, 0)

        def HALT(self):
            return self.getToken(krlParser.HALT, 0)

        def IF(self):
            return self.getToken(krlParser.IF, 0)

        def THEN(self):
            return self.getToken(krlParser.THEN, 0)

        def ENDIF(self):
            return self.getToken(krlParser.ENDIF, 0)

        def ELSE(self):
            return self.getToken(krlParser.ELSE, 0)

        def LOOP(self):
            return self.getToken(krlParser.LOOP, 0)

        def ENDLOOP(self):
            return self.getToken(krlParser.ENDLOOP, 0)

        def REPEAT(self):
            return self.getToken(krlParser.REPEAT, 0)

        def UNTIL(self):
            return self.getToken(krlParser.UNTIL, 0)

        def SWITCH(self):
            return self.getToken(krlParser.SWITCH, 0)

        def switchBlockStatementGroups(self):
            return self.getTypedRuleContext(krlParser.SwitchBlockStatementGroupsContext,0)


        def ENDSWITCH(self):
            return self.getToken(krlParser.ENDSWITCH, 0)

        def WAIT(self):
            return self.getToken(krlParser.WAIT, 0)

        def SEC(self):
            return self.getToken(krlParser.SEC, 0)

        def WHILE(self):
            return self.getToken(krlParser.WHILE, 0)

        def ENDWHILE(self):
            return self.getToken(krlParser.ENDWHILE, 0)

        def RETURN(self):
            return self.getToken(krlParser.RETURN, 0)

        def assignmentExpression(self):
            return self.getTypedRuleContext(krlParser.AssignmentExpressionContext,0)


        def BRAKE(self):
            return self.getToken(krlParser.BRAKE, 0)

        def INTERRUPT(self):
            return self.getToken(krlParser.INTERRUPT, 0)

        def DECL(self):
            return self.getToken(krlParser.DECL, 0)

        def primary(self):
            return self.getTypedRuleContext(krlParser.PrimaryContext,0)


        def WHEN(self):
            return self.getToken(krlParser.WHEN, 0)

        def DO(self):
            return self.getToken(krlParser.DO, 0)

        def GLOBAL(self):
            return self.getToken(krlParser.GLOBAL, 0)

        def geometricExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.GeometricExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.GeometricExpressionContext,i)


        def PTP(self):
            return self.getToken(krlParser.PTP, 0)

        def PTP_REL(self):
            return self.getToken(krlParser.PTP_REL, 0)

        def C_PTP(self):
            return self.getToken(krlParser.C_PTP, 0)

        def C_DIS(self):
            return self.getToken(krlParser.C_DIS, 0)

        def C_ORI(self):
            return self.getToken(krlParser.C_ORI, 0)

        def C_VEL(self):
            return self.getToken(krlParser.C_VEL, 0)

        def LIN(self):
            return self.getToken(krlParser.LIN, 0)

        def LIN_REL(self):
            return self.getToken(krlParser.LIN_REL, 0)

        def enumElement(self):
            return self.getTypedRuleContext(krlParser.EnumElementContext,0)


        def CIRC(self):
            return self.getToken(krlParser.CIRC, 0)

        def CIRC_REL(self):
            return self.getToken(krlParser.CIRC_REL, 0)

        def TRIGGER(self):
            return self.getToken(krlParser.TRIGGER, 0)

        def DELAY(self):
            return self.getToken(krlParser.DELAY, 0)

        def PRIO(self):
            return self.getToken(krlParser.PRIO, 0)

        def analogInputStatement(self):
            return self.getTypedRuleContext(krlParser.AnalogInputStatementContext,0)


        def analogOutputStatement(self):
            return self.getTypedRuleContext(krlParser.AnalogOutputStatementContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_statement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterStatement" ):
                listener.enterStatement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitStatement" ):
                listener.exitStatement(self)




    def statement(self):

        localctx = krlParser.StatementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 74, self.RULE_statement)
        self._la = 0 # Token type
        try:
            self.state = 595
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,57,self._ctx)
            if la_ == 1:
                self.enterOuterAlt(localctx, 1)
                self.state = 423
                self.match(krlParser.CONTINUE)
                self.state = 424
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 2:
                self.enterOuterAlt(localctx, 2)
                self.state = 425
                self.match(krlParser.EXIT)
                self.state = 426
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 3:
                self.enterOuterAlt(localctx, 3)
                self.state = 427
                self.match(krlParser.FOR)
                self.state = 428
                self.match(krlParser.IDENTIFIER)
                self.state = 429
                self.match(krlParser.T__0)
                self.state = 430
                self.expression()
                self.state = 431
                self.match(krlParser.TO)
                self.state = 432
                self.expression()
                self.state = 435
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==110:
                    self.state = 433
                    self.match(krlParser.IDENTIFIER)
                    self.state = 434
                    self.expression()


                self.state = 437
                self.match(krlParser.NEWLINE)
                self.state = 438
                self.statementList()
                self.state = 439
                self.match(krlParser.ENDFOR)
                pass

            elif la_ == 4:
                self.enterOuterAlt(localctx, 4)
                self.state = 441
                self.match(krlParser.GOTO)
                self.state = 442
                self.match(krlParser.IDENTIFIER)
                self.state = 443
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 5:
                self.enterOuterAlt(localctx, 5)
                self.state = 444
                self.match(krlParser.HALT)
                self.state = 445
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 6:
                self.enterOuterAlt(localctx, 6)
                self.state = 446
                self.match(krlParser.IF)
                self.state = 447
                self.expression()
                self.state = 448
                self.match(krlParser.THEN)
                self.state = 449
                self.match(krlParser.NEWLINE)
                self.state = 450
                self.statementList()
                self.state = 454
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==52:
                    self.state = 451
                    self.match(krlParser.ELSE)
                    self.state = 452
                    self.match(krlParser.NEWLINE)
                    self.state = 453
                    self.statementList()


                self.state = 456
                self.match(krlParser.ENDIF)
                self.state = 457
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 7:
                self.enterOuterAlt(localctx, 7)
                self.state = 459
                self.match(krlParser.LOOP)
                self.state = 460
                self.match(krlParser.NEWLINE)
                self.state = 461
                self.statementList()
                self.state = 462
                self.match(krlParser.ENDLOOP)
                self.state = 463
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 8:
                self.enterOuterAlt(localctx, 8)
                self.state = 465
                self.match(krlParser.REPEAT)
                self.state = 466
                self.match(krlParser.NEWLINE)
                self.state = 467
                self.statementList()
                self.state = 468
                self.match(krlParser.UNTIL)
                self.state = 469
                self.expression()
                self.state = 470
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 9:
                self.enterOuterAlt(localctx, 9)
                self.state = 472
                self.match(krlParser.SWITCH)
                self.state = 473
                self.expression()
                self.state = 474
                self.match(krlParser.NEWLINE)
                self.state = 475
                self.switchBlockStatementGroups()
                self.state = 476
                self.match(krlParser.ENDSWITCH)
                self.state = 477
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 10:
                self.enterOuterAlt(localctx, 10)
                self.state = 479
                self.match(krlParser.WAIT)
                self.state = 480
                self.match(krlParser.FOR)
                self.state = 481
                self.expression()
                self.state = 482
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 11:
                self.enterOuterAlt(localctx, 11)
                self.state = 484
                self.match(krlParser.WAIT)
                self.state = 485
                self.match(krlParser.SEC)
                self.state = 486
                self.expression()
                self.state = 487
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 12:
                self.enterOuterAlt(localctx, 12)
                self.state = 489
                self.match(krlParser.WHILE)
                self.state = 490
                self.expression()
                self.state = 491
                self.match(krlParser.NEWLINE)
                self.state = 492
                self.statementList()
                self.state = 493
                self.match(krlParser.ENDWHILE)
                self.state = 494
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 13:
                self.enterOuterAlt(localctx, 13)
                self.state = 496
                self.match(krlParser.RETURN)
                self.state = 498
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if (((_la) & ~0x3f) == 0 and ((1 << _la) & 277610568) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868438529) != 0):
                    self.state = 497
                    self.assignmentExpression()


                self.state = 500
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 14:
                self.enterOuterAlt(localctx, 14)
                self.state = 501
                self.match(krlParser.BRAKE)
                self.state = 503
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==110:
                    self.state = 502
                    self.match(krlParser.IDENTIFIER)


                self.state = 505
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 15:
                self.enterOuterAlt(localctx, 15)
                self.state = 506
                self.assignmentExpression()
                self.state = 507
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 16:
                self.enterOuterAlt(localctx, 16)
                self.state = 509
                self.match(krlParser.IDENTIFIER)
                self.state = 510
                self.match(krlParser.T__3)
                self.state = 511
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 17:
                self.enterOuterAlt(localctx, 17)
                self.state = 512
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 18:
                self.enterOuterAlt(localctx, 18)
                self.state = 514
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==67:
                    self.state = 513
                    self.match(krlParser.GLOBAL)


                self.state = 516
                self.match(krlParser.INTERRUPT)
                self.state = 517
                self.match(krlParser.DECL)
                self.state = 518
                self.primary()
                self.state = 519
                self.match(krlParser.WHEN)
                self.state = 520
                self.expression()
                self.state = 521
                self.match(krlParser.DO)
                self.state = 522
                self.assignmentExpression()
                self.state = 523
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 19:
                self.enterOuterAlt(localctx, 19)
                self.state = 525
                self.match(krlParser.INTERRUPT)
                self.state = 526
                self.match(krlParser.IDENTIFIER)
                self.state = 528
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if (((_la) & ~0x3f) == 0 and ((1 << _la) & 8388680) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868405761) != 0):
                    self.state = 527
                    self.primary()


                self.state = 530
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 20:
                self.enterOuterAlt(localctx, 20)
                self.state = 531
                _la = self._input.LA(1)
                if not(_la==83 or _la==84):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 532
                self.geometricExpression()
                self.state = 537
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==35:
                    self.state = 533
                    self.match(krlParser.C_PTP)
                    self.state = 535
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)
                    if (((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0):
                        self.state = 534
                        _la = self._input.LA(1)
                        if not((((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0)):
                            self._errHandler.recoverInline(self)
                        else:
                            self._errHandler.reportMatch(self)
                            self.consume()




                self.state = 539
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 21:
                self.enterOuterAlt(localctx, 21)
                self.state = 541
                self.match(krlParser.LIN)
                self.state = 542
                self.geometricExpression()
                self.state = 544
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if (((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0):
                    self.state = 543
                    _la = self._input.LA(1)
                    if not((((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0)):
                        self._errHandler.recoverInline(self)
                    else:
                        self._errHandler.reportMatch(self)
                        self.consume()


                self.state = 546
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 22:
                self.enterOuterAlt(localctx, 22)
                self.state = 548
                self.match(krlParser.LIN_REL)
                self.state = 549
                self.geometricExpression()
                self.state = 551
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if (((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0):
                    self.state = 550
                    _la = self._input.LA(1)
                    if not((((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0)):
                        self._errHandler.recoverInline(self)
                    else:
                        self._errHandler.reportMatch(self)
                        self.consume()


                self.state = 554
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==23:
                    self.state = 553
                    self.enumElement()


                self.state = 556
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 23:
                self.enterOuterAlt(localctx, 23)
                self.state = 558
                _la = self._input.LA(1)
                if not(_la==41 or _la==42):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 559
                self.geometricExpression()
                self.state = 560
                self.match(krlParser.T__1)
                self.state = 561
                self.geometricExpression()
                self.state = 565
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==2:
                    self.state = 562
                    self.match(krlParser.T__1)
                    self.state = 563
                    self.match(krlParser.IDENTIFIER)
                    self.state = 564
                    self.primary()


                self.state = 568
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if (((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0):
                    self.state = 567
                    _la = self._input.LA(1)
                    if not((((_la) & ~0x3f) == 0 and ((1 << _la) & 94489280512) != 0)):
                        self._errHandler.recoverInline(self)
                    else:
                        self._errHandler.reportMatch(self)
                        self.consume()


                self.state = 570
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 24:
                self.enterOuterAlt(localctx, 24)
                self.state = 572
                self.match(krlParser.TRIGGER)
                self.state = 573
                self.match(krlParser.WHEN)

                self.state = 574
                self.match(krlParser.IDENTIFIER)
                self.state = 575
                self.match(krlParser.T__0)
                self.state = 576
                self.expression()
                self.state = 577
                self.match(krlParser.DELAY)
                self.state = 578
                self.match(krlParser.T__0)
                self.state = 579
                self.expression()
                self.state = 580
                self.match(krlParser.DO)
                self.state = 581
                self.assignmentExpression()
                self.state = 585
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==82:
                    self.state = 582
                    self.match(krlParser.PRIO)
                    self.state = 583
                    self.match(krlParser.T__0)
                    self.state = 584
                    self.expression()


                self.state = 587
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 25:
                self.enterOuterAlt(localctx, 25)
                self.state = 589
                self.analogInputStatement()
                self.state = 590
                self.match(krlParser.NEWLINE)
                pass

            elif la_ == 26:
                self.enterOuterAlt(localctx, 26)
                self.state = 592
                self.analogOutputStatement()
                self.state = 593
                self.match(krlParser.NEWLINE)
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class AnalogOutputStatementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def ANOUT(self):
            return self.getToken(krlParser.ANOUT, 0)

        def IDENTIFIER(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.IDENTIFIER)
            else:
                return self.getToken(krlParser.IDENTIFIER, i)

        def assignmentExpression(self):
            return self.getTypedRuleContext(krlParser.AssignmentExpressionContext,0)


        def literal(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.LiteralContext)
            else:
                return self.getTypedRuleContext(krlParser.LiteralContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_analogOutputStatement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterAnalogOutputStatement" ):
                listener.enterAnalogOutputStatement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitAnalogOutputStatement" ):
                listener.exitAnalogOutputStatement(self)




    def analogOutputStatement(self):

        localctx = krlParser.AnalogOutputStatementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 76, self.RULE_analogOutputStatement)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 597
            self.match(krlParser.ANOUT)
            self.state = 610
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,59,self._ctx)
            if la_ == 1:
                self.state = 598
                self.match(krlParser.IDENTIFIER)
                self.state = 599
                self.assignmentExpression()
                self.state = 605
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                while _la==110:
                    self.state = 600
                    self.match(krlParser.IDENTIFIER)
                    self.state = 601
                    self.match(krlParser.T__0)
                    self.state = 602
                    self.literal()
                    self.state = 607
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)

                pass

            elif la_ == 2:
                self.state = 608
                self.match(krlParser.IDENTIFIER)
                self.state = 609
                self.match(krlParser.IDENTIFIER)
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class AnalogInputStatementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def ANIN(self):
            return self.getToken(krlParser.ANIN, 0)

        def IDENTIFIER(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.IDENTIFIER)
            else:
                return self.getToken(krlParser.IDENTIFIER, i)

        def assignmentExpression(self):
            return self.getTypedRuleContext(krlParser.AssignmentExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_analogInputStatement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterAnalogInputStatement" ):
                listener.enterAnalogInputStatement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitAnalogInputStatement" ):
                listener.exitAnalogInputStatement(self)




    def analogInputStatement(self):

        localctx = krlParser.AnalogInputStatementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 78, self.RULE_analogInputStatement)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 612
            self.match(krlParser.ANIN)
            self.state = 617
            self._errHandler.sync(self)
            la_ = self._interp.adaptivePredict(self._input,60,self._ctx)
            if la_ == 1:
                self.state = 613
                self.match(krlParser.IDENTIFIER)
                self.state = 614
                self.assignmentExpression()
                pass

            elif la_ == 2:
                self.state = 615
                self.match(krlParser.IDENTIFIER)
                self.state = 616
                self.match(krlParser.IDENTIFIER)
                pass


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class SwitchBlockStatementGroupsContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def NEWLINE(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.NEWLINE)
            else:
                return self.getToken(krlParser.NEWLINE, i)

        def caseLabel(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.CaseLabelContext)
            else:
                return self.getTypedRuleContext(krlParser.CaseLabelContext,i)


        def statementList(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.StatementListContext)
            else:
                return self.getTypedRuleContext(krlParser.StatementListContext,i)


        def defaultLabel(self):
            return self.getTypedRuleContext(krlParser.DefaultLabelContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_switchBlockStatementGroups

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterSwitchBlockStatementGroups" ):
                listener.enterSwitchBlockStatementGroups(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitSwitchBlockStatementGroups" ):
                listener.exitSwitchBlockStatementGroups(self)




    def switchBlockStatementGroups(self):

        localctx = krlParser.SwitchBlockStatementGroupsContext(self, self._ctx, self.state)
        self.enterRule(localctx, 80, self.RULE_switchBlockStatementGroups)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 622
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==104:
                self.state = 619
                self.match(krlParser.NEWLINE)
                self.state = 624
                self._errHandler.sync(self)
                _la = self._input.LA(1)

            self.state = 628 
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while True:
                self.state = 625
                self.caseLabel()
                self.state = 626
                self.statementList()
                self.state = 630 
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if not (_la==37):
                    break

            self.state = 635
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if _la==48:
                self.state = 632
                self.defaultLabel()
                self.state = 633
                self.statementList()


        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class CaseLabelContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def CASE(self):
            return self.getToken(krlParser.CASE, 0)

        def expression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ExpressionContext,i)


        def NEWLINE(self):
            return self.getToken(krlParser.NEWLINE, 0)

        def getRuleIndex(self):
            return krlParser.RULE_caseLabel

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterCaseLabel" ):
                listener.enterCaseLabel(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitCaseLabel" ):
                listener.exitCaseLabel(self)




    def caseLabel(self):

        localctx = krlParser.CaseLabelContext(self, self._ctx, self.state)
        self.enterRule(localctx, 82, self.RULE_caseLabel)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 637
            self.match(krlParser.CASE)
            self.state = 638
            self.expression()
            self.state = 643
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==2:
                self.state = 639
                self.match(krlParser.T__1)
                self.state = 640
                self.expression()
                self.state = 645
                self._errHandler.sync(self)
                _la = self._input.LA(1)

            self.state = 646
            self.match(krlParser.NEWLINE)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class DefaultLabelContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def DEFAULT(self):
            return self.getToken(krlParser.DEFAULT, 0)

        def NEWLINE(self):
            return self.getToken(krlParser.NEWLINE, 0)

        def getRuleIndex(self):
            return krlParser.RULE_defaultLabel

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterDefaultLabel" ):
                listener.enterDefaultLabel(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitDefaultLabel" ):
                listener.exitDefaultLabel(self)




    def defaultLabel(self):

        localctx = krlParser.DefaultLabelContext(self, self._ctx, self.state)
        self.enterRule(localctx, 84, self.RULE_defaultLabel)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 648
            self.match(krlParser.DEFAULT)
            self.state = 649
            self.match(krlParser.NEWLINE)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ExpressionListContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def assignmentExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.AssignmentExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.AssignmentExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_expressionList

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterExpressionList" ):
                listener.enterExpressionList(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitExpressionList" ):
                listener.exitExpressionList(self)




    def expressionList(self):

        localctx = krlParser.ExpressionListContext(self, self._ctx, self.state)
        self.enterRule(localctx, 86, self.RULE_expressionList)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 651
            self.assignmentExpression()
            self.state = 656
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==2:
                self.state = 652
                self.match(krlParser.T__1)
                self.state = 653
                self.assignmentExpression()
                self.state = 658
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class AssignmentExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def expression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_assignmentExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterAssignmentExpression" ):
                listener.enterAssignmentExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitAssignmentExpression" ):
                listener.exitAssignmentExpression(self)




    def assignmentExpression(self):

        localctx = krlParser.AssignmentExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 88, self.RULE_assignmentExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 659
            self.expression()
            self.state = 664
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==1:
                self.state = 660
                self.match(krlParser.T__0)
                self.state = 661
                self.expression()
                self.state = 666
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def conditionalOrExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ConditionalOrExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ConditionalOrExpressionContext,i)


        def relationalOp(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.RelationalOpContext)
            else:
                return self.getTypedRuleContext(krlParser.RelationalOpContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_expression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterExpression" ):
                listener.enterExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitExpression" ):
                listener.exitExpression(self)




    def expression(self):

        localctx = krlParser.ExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 90, self.RULE_expression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 667
            self.conditionalOrExpression()
            self.state = 673
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while (((_la) & ~0x3f) == 0 and ((1 << _la) & 258048) != 0):
                self.state = 668
                self.relationalOp()
                self.state = 669
                self.conditionalOrExpression()
                self.state = 675
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class RelationalOpContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser


        def getRuleIndex(self):
            return krlParser.RULE_relationalOp

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterRelationalOp" ):
                listener.enterRelationalOp(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitRelationalOp" ):
                listener.exitRelationalOp(self)




    def relationalOp(self):

        localctx = krlParser.RelationalOpContext(self, self._ctx, self.state)
        self.enterRule(localctx, 92, self.RULE_relationalOp)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 676
            _la = self._input.LA(1)
            if not((((_la) & ~0x3f) == 0 and ((1 << _la) & 258048) != 0)):
                self._errHandler.recoverInline(self)
            else:
                self._errHandler.reportMatch(self)
                self.consume()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ConditionalOrExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def exclusiveOrExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ExclusiveOrExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ExclusiveOrExpressionContext,i)


        def OR(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.OR)
            else:
                return self.getToken(krlParser.OR, i)

        def B_OR(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.B_OR)
            else:
                return self.getToken(krlParser.B_OR, i)

        def getRuleIndex(self):
            return krlParser.RULE_conditionalOrExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterConditionalOrExpression" ):
                listener.enterConditionalOrExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitConditionalOrExpression" ):
                listener.exitConditionalOrExpression(self)




    def conditionalOrExpression(self):

        localctx = krlParser.ConditionalOrExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 94, self.RULE_conditionalOrExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 678
            self.exclusiveOrExpression()
            self.state = 683
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==29 or _la==81:
                self.state = 679
                _la = self._input.LA(1)
                if not(_la==29 or _la==81):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 680
                self.exclusiveOrExpression()
                self.state = 685
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ExclusiveOrExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def conditionalAndExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.ConditionalAndExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.ConditionalAndExpressionContext,i)


        def EXOR(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.EXOR)
            else:
                return self.getToken(krlParser.EXOR, i)

        def B_EXOR(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.B_EXOR)
            else:
                return self.getToken(krlParser.B_EXOR, i)

        def getRuleIndex(self):
            return krlParser.RULE_exclusiveOrExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterExclusiveOrExpression" ):
                listener.enterExclusiveOrExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitExclusiveOrExpression" ):
                listener.exitExclusiveOrExpression(self)




    def exclusiveOrExpression(self):

        localctx = krlParser.ExclusiveOrExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 96, self.RULE_exclusiveOrExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 686
            self.conditionalAndExpression()
            self.state = 691
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==30 or _la==101:
                self.state = 687
                _la = self._input.LA(1)
                if not(_la==30 or _la==101):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 688
                self.conditionalAndExpression()
                self.state = 693
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ConditionalAndExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def additiveExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.AdditiveExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.AdditiveExpressionContext,i)


        def AND(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.AND)
            else:
                return self.getToken(krlParser.AND, i)

        def B_AND(self, i:int=None):
            if i is None:
                return self.getTokens(krlParser.B_AND)
            else:
                return self.getToken(krlParser.B_AND, i)

        def getRuleIndex(self):
            return krlParser.RULE_conditionalAndExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterConditionalAndExpression" ):
                listener.enterConditionalAndExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitConditionalAndExpression" ):
                listener.exitConditionalAndExpression(self)




    def conditionalAndExpression(self):

        localctx = krlParser.ConditionalAndExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 98, self.RULE_conditionalAndExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 694
            self.additiveExpression()
            self.state = 699
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==24 or _la==27:
                self.state = 695
                _la = self._input.LA(1)
                if not(_la==24 or _la==27):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 696
                self.additiveExpression()
                self.state = 701
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class AdditiveExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def multiplicativeExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.MultiplicativeExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.MultiplicativeExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_additiveExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterAdditiveExpression" ):
                listener.enterAdditiveExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitAdditiveExpression" ):
                listener.exitAdditiveExpression(self)




    def additiveExpression(self):

        localctx = krlParser.AdditiveExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 100, self.RULE_additiveExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 702
            self.multiplicativeExpression()
            self.state = 707
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==18 or _la==19:
                self.state = 703
                _la = self._input.LA(1)
                if not(_la==18 or _la==19):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 704
                self.multiplicativeExpression()
                self.state = 709
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class MultiplicativeExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def geometricExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.GeometricExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.GeometricExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_multiplicativeExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterMultiplicativeExpression" ):
                listener.enterMultiplicativeExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitMultiplicativeExpression" ):
                listener.exitMultiplicativeExpression(self)




    def multiplicativeExpression(self):

        localctx = krlParser.MultiplicativeExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 102, self.RULE_multiplicativeExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 710
            self.geometricExpression()
            self.state = 715
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==20 or _la==21:
                self.state = 711
                _la = self._input.LA(1)
                if not(_la==20 or _la==21):
                    self._errHandler.recoverInline(self)
                else:
                    self._errHandler.reportMatch(self)
                    self.consume()
                self.state = 712
                self.geometricExpression()
                self.state = 717
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class GeometricExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def unaryNotExpression(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.UnaryNotExpressionContext)
            else:
                return self.getTypedRuleContext(krlParser.UnaryNotExpressionContext,i)


        def getRuleIndex(self):
            return krlParser.RULE_geometricExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterGeometricExpression" ):
                listener.enterGeometricExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitGeometricExpression" ):
                listener.exitGeometricExpression(self)




    def geometricExpression(self):

        localctx = krlParser.GeometricExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 104, self.RULE_geometricExpression)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 718
            self.unaryNotExpression()
            self.state = 723
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            while _la==4:
                self.state = 719
                self.match(krlParser.T__3)
                self.state = 720
                self.unaryNotExpression()
                self.state = 725
                self._errHandler.sync(self)
                _la = self._input.LA(1)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class UnaryNotExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def NOT(self):
            return self.getToken(krlParser.NOT, 0)

        def unaryNotExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryNotExpressionContext,0)


        def B_NOT(self):
            return self.getToken(krlParser.B_NOT, 0)

        def unaryPlusMinuxExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryPlusMinuxExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_unaryNotExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterUnaryNotExpression" ):
                listener.enterUnaryNotExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitUnaryNotExpression" ):
                listener.exitUnaryNotExpression(self)




    def unaryNotExpression(self):

        localctx = krlParser.UnaryNotExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 106, self.RULE_unaryNotExpression)
        try:
            self.state = 731
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [80]:
                self.enterOuterAlt(localctx, 1)
                self.state = 726
                self.match(krlParser.NOT)
                self.state = 727
                self.unaryNotExpression()
                pass
            elif token in [28]:
                self.enterOuterAlt(localctx, 2)
                self.state = 728
                self.match(krlParser.B_NOT)
                self.state = 729
                self.unaryNotExpression()
                pass
            elif token in [3, 6, 18, 19, 23, 65, 96, 106, 107, 108, 109, 110]:
                self.enterOuterAlt(localctx, 3)
                self.state = 730
                self.unaryPlusMinuxExpression()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class UnaryPlusMinuxExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def unaryPlusMinuxExpression(self):
            return self.getTypedRuleContext(krlParser.UnaryPlusMinuxExpressionContext,0)


        def primary(self):
            return self.getTypedRuleContext(krlParser.PrimaryContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_unaryPlusMinuxExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterUnaryPlusMinuxExpression" ):
                listener.enterUnaryPlusMinuxExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitUnaryPlusMinuxExpression" ):
                listener.exitUnaryPlusMinuxExpression(self)




    def unaryPlusMinuxExpression(self):

        localctx = krlParser.UnaryPlusMinuxExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 108, self.RULE_unaryPlusMinuxExpression)
        try:
            self.state = 738
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [18]:
                self.enterOuterAlt(localctx, 1)
                self.state = 733
                self.match(krlParser.T__17)
                self.state = 734
                self.unaryPlusMinuxExpression()
                pass
            elif token in [19]:
                self.enterOuterAlt(localctx, 2)
                self.state = 735
                self.match(krlParser.T__18)
                self.state = 736
                self.unaryPlusMinuxExpression()
                pass
            elif token in [3, 6, 23, 65, 96, 106, 107, 108, 109, 110]:
                self.enterOuterAlt(localctx, 3)
                self.state = 737
                self.primary()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class PrimaryContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def parExpression(self):
            return self.getTypedRuleContext(krlParser.ParExpressionContext,0)


        def variableName(self, i:int=None):
            if i is None:
                return self.getTypedRuleContexts(krlParser.VariableNameContext)
            else:
                return self.getTypedRuleContext(krlParser.VariableNameContext,i)


        def arguments(self):
            return self.getTypedRuleContext(krlParser.ArgumentsContext,0)


        def literal(self):
            return self.getTypedRuleContext(krlParser.LiteralContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_primary

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterPrimary" ):
                listener.enterPrimary(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitPrimary" ):
                listener.exitPrimary(self)




    def primary(self):

        localctx = krlParser.PrimaryContext(self, self._ctx, self.state)
        self.enterRule(localctx, 110, self.RULE_primary)
        self._la = 0 # Token type
        try:
            self.state = 753
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [6]:
                self.enterOuterAlt(localctx, 1)
                self.state = 740
                self.parExpression()
                pass
            elif token in [110]:
                self.enterOuterAlt(localctx, 2)
                self.state = 741
                self.variableName()
                self.state = 746
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                while _la==22:
                    self.state = 742
                    self.match(krlParser.T__21)
                    self.state = 743
                    self.variableName()
                    self.state = 748
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)

                self.state = 750
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==6:
                    self.state = 749
                    self.arguments()


                pass
            elif token in [3, 23, 65, 96, 106, 107, 108, 109]:
                self.enterOuterAlt(localctx, 3)
                self.state = 752
                self.literal()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ParExpressionContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def assignmentExpression(self):
            return self.getTypedRuleContext(krlParser.AssignmentExpressionContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_parExpression

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterParExpression" ):
                listener.enterParExpression(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitParExpression" ):
                listener.exitParExpression(self)




    def parExpression(self):

        localctx = krlParser.ParExpressionContext(self, self._ctx, self.state)
        self.enterRule(localctx, 112, self.RULE_parExpression)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 755
            self.match(krlParser.T__5)
            self.state = 756
            self.assignmentExpression()
            self.state = 757
            self.match(krlParser.T__6)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class Type_Context(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def primitiveType(self):
            return self.getTypedRuleContext(krlParser.PrimitiveTypeContext,0)


        def INTLITERAL(self):
            return self.getToken(krlParser.INTLITERAL, 0)

        def typeName(self):
            return self.getTypedRuleContext(krlParser.TypeNameContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_type_

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterType_" ):
                listener.enterType_(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitType_" ):
                listener.exitType_(self)




    def type_(self):

        localctx = krlParser.Type_Context(self, self._ctx, self.state)
        self.enterRule(localctx, 114, self.RULE_type_)
        self._la = 0 # Token type
        try:
            self.state = 775
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [31, 40, 73, 86]:
                self.enterOuterAlt(localctx, 1)
                self.state = 759
                self.primitiveType()
                self.state = 765
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==10:
                    self.state = 760
                    self.match(krlParser.T__9)
                    self.state = 762
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)
                    if _la==109:
                        self.state = 761
                        self.match(krlParser.INTLITERAL)


                    self.state = 764
                    self.match(krlParser.T__10)


                pass
            elif token in [110]:
                self.enterOuterAlt(localctx, 2)
                self.state = 767
                self.typeName()
                self.state = 773
                self._errHandler.sync(self)
                _la = self._input.LA(1)
                if _la==10:
                    self.state = 768
                    self.match(krlParser.T__9)
                    self.state = 770
                    self._errHandler.sync(self)
                    _la = self._input.LA(1)
                    if _la==109:
                        self.state = 769
                        self.match(krlParser.INTLITERAL)


                    self.state = 772
                    self.match(krlParser.T__10)


                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class TypeNameContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_typeName

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterTypeName" ):
                listener.enterTypeName(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitTypeName" ):
                listener.exitTypeName(self)




    def typeName(self):

        localctx = krlParser.TypeNameContext(self, self._ctx, self.state)
        self.enterRule(localctx, 116, self.RULE_typeName)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 777
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class PrimitiveTypeContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def BOOL(self):
            return self.getToken(krlParser.BOOL, 0)

        def CHAR(self):
            return self.getToken(krlParser.CHAR, 0)

        def INT(self):
            return self.getToken(krlParser.INT, 0)

        def REAL(self):
            return self.getToken(krlParser.REAL, 0)

        def getRuleIndex(self):
            return krlParser.RULE_primitiveType

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterPrimitiveType" ):
                listener.enterPrimitiveType(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitPrimitiveType" ):
                listener.exitPrimitiveType(self)




    def primitiveType(self):

        localctx = krlParser.PrimitiveTypeContext(self, self._ctx, self.state)
        self.enterRule(localctx, 118, self.RULE_primitiveType)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 779
            _la = self._input.LA(1)
            if not(((((_la - 31)) & ~0x3f) == 0 and ((1 << (_la - 31)) & 36033195065475585) != 0)):
                self._errHandler.recoverInline(self)
            else:
                self._errHandler.reportMatch(self)
                self.consume()
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class ArgumentsContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def expressionList(self):
            return self.getTypedRuleContext(krlParser.ExpressionListContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_arguments

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterArguments" ):
                listener.enterArguments(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitArguments" ):
                listener.exitArguments(self)




    def arguments(self):

        localctx = krlParser.ArgumentsContext(self, self._ctx, self.state)
        self.enterRule(localctx, 120, self.RULE_arguments)
        self._la = 0 # Token type
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 781
            self.match(krlParser.T__5)
            self.state = 783
            self._errHandler.sync(self)
            _la = self._input.LA(1)
            if (((_la) & ~0x3f) == 0 and ((1 << _la) & 277610568) != 0) or ((((_la - 65)) & ~0x3f) == 0 and ((1 << (_la - 65)) & 68171868438529) != 0):
                self.state = 782
                self.expressionList()


            self.state = 785
            self.match(krlParser.T__6)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class LiteralContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def INTLITERAL(self):
            return self.getToken(krlParser.INTLITERAL, 0)

        def FLOATLITERAL(self):
            return self.getToken(krlParser.FLOATLITERAL, 0)

        def CHARLITERAL(self):
            return self.getToken(krlParser.CHARLITERAL, 0)

        def STRINGLITERAL(self):
            return self.getToken(krlParser.STRINGLITERAL, 0)

        def structLiteral(self):
            return self.getTypedRuleContext(krlParser.StructLiteralContext,0)


        def TRUE(self):
            return self.getToken(krlParser.TRUE, 0)

        def FALSE(self):
            return self.getToken(krlParser.FALSE, 0)

        def enumElement(self):
            return self.getTypedRuleContext(krlParser.EnumElementContext,0)


        def getRuleIndex(self):
            return krlParser.RULE_literal

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterLiteral" ):
                listener.enterLiteral(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitLiteral" ):
                listener.exitLiteral(self)




    def literal(self):

        localctx = krlParser.LiteralContext(self, self._ctx, self.state)
        self.enterRule(localctx, 122, self.RULE_literal)
        try:
            self.state = 795
            self._errHandler.sync(self)
            token = self._input.LA(1)
            if token in [109]:
                self.enterOuterAlt(localctx, 1)
                self.state = 787
                self.match(krlParser.INTLITERAL)
                pass
            elif token in [108]:
                self.enterOuterAlt(localctx, 2)
                self.state = 788
                self.match(krlParser.FLOATLITERAL)
                pass
            elif token in [106]:
                self.enterOuterAlt(localctx, 3)
                self.state = 789
                self.match(krlParser.CHARLITERAL)
                pass
            elif token in [107]:
                self.enterOuterAlt(localctx, 4)
                self.state = 790
                self.match(krlParser.STRINGLITERAL)
                pass
            elif token in [3]:
                self.enterOuterAlt(localctx, 5)
                self.state = 791
                self.structLiteral()
                pass
            elif token in [96]:
                self.enterOuterAlt(localctx, 6)
                self.state = 792
                self.match(krlParser.TRUE)
                pass
            elif token in [65]:
                self.enterOuterAlt(localctx, 7)
                self.state = 793
                self.match(krlParser.FALSE)
                pass
            elif token in [23]:
                self.enterOuterAlt(localctx, 8)
                self.state = 794
                self.enumElement()
                pass
            else:
                raise NoViableAltException(self)

        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx


    class EnumElementContext(ParserRuleContext):
        __slots__ = 'parser'

        def __init__(self, parser, parent:ParserRuleContext=None, invokingState:int=-1):
            super().__init__(parent, invokingState)
            self.parser = parser

        def IDENTIFIER(self):
            return self.getToken(krlParser.IDENTIFIER, 0)

        def getRuleIndex(self):
            return krlParser.RULE_enumElement

        def enterRule(self, listener:ParseTreeListener):
            if hasattr( listener, "enterEnumElement" ):
                listener.enterEnumElement(self)

        def exitRule(self, listener:ParseTreeListener):
            if hasattr( listener, "exitEnumElement" ):
                listener.exitEnumElement(self)




    def enumElement(self):

        localctx = krlParser.EnumElementContext(self, self._ctx, self.state)
        self.enterRule(localctx, 124, self.RULE_enumElement)
        try:
            self.enterOuterAlt(localctx, 1)
            self.state = 797
            self.match(krlParser.T__22)
            self.state = 798
            self.match(krlParser.IDENTIFIER)
        except RecognitionException as re:
            localctx.exception = re
            self._errHandler.reportError(self, re)
            self._errHandler.recover(self, re)
        finally:
            self.exitRule()
        return localctx





