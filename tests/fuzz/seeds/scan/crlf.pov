a
bc
﻿"unterminated